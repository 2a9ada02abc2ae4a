#include "server_config.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <thread>

namespace k4reg::service {

void add_config_options(CLI::App& app, ServerConfig& c) {
  app.add_option("--grpc-listen", c.grpc_listen, "gRPC address host:port (port 0 = ephemeral)")
      ->envname("K4REG_GRPC_LISTEN")
      ->capture_default_str();
  app.add_option("--http-listen", c.http_listen,
                 "HTTP/JSON API and /metrics address host:port (port 0 = ephemeral, empty = no HTTP)")
      ->envname("K4REG_HTTP_LISTEN")
      ->capture_default_str();
  app.add_option("--health-listen", c.health_listen,
                 "plaintext listener for probes only (gRPC health, GET /healthz and /readyz), host:port; "
                 "empty = none")
      ->envname("K4REG_HEALTH_LISTEN");
  app.add_option("--port-file", c.port_file, "write the bound gRPC port to this file once serving")
      ->envname("K4REG_PORT_FILE");
  app.add_option("--http-port-file", c.http_port_file, "write the bound HTTP port to this file once serving")
      ->envname("K4REG_HTTP_PORT_FILE");
  app.add_option("--data-root", c.data_roots, "folder whose files requests may reference (repeatable; env: colon-separated)")
      ->envname("K4REG_DATA_ROOT")
      ->delimiter(':')
      ->check(CLI::ExistingDirectory);
  app.add_option("--workers", c.workers, "concurrent jobs, 0 = number of cores")->envname("K4REG_WORKERS");
  app.add_option("--queue-size", c.queue_size, "jobs that may wait for a worker; beyond: RESOURCE_EXHAUSTED")
      ->envname("K4REG_QUEUE_SIZE")
      ->capture_default_str();
  app.add_option("--peers", c.peers,
                 "gRPC target of the replicas a project's pairs are sent to (e.g. dns:///k4reg-headless:50051, round "
                 "robin over its addresses); empty = every pair in this process")
      ->envname("K4REG_PEERS");
  app.add_option("--pair-workers", c.pair_workers, "pairs of other replicas' projects run at once, 0 = --workers")
      ->envname("K4REG_PAIR_WORKERS");
  app.add_option("--pair-queue-size", c.pair_queue_size, "pairs that may wait; beyond: RESOURCE_EXHAUSTED")
      ->envname("K4REG_PAIR_QUEUE_SIZE")
      ->capture_default_str();
  app.add_option("--pair-cache-mb", c.pair_cache_mb,
                 "scans of other replicas' pair jobs kept with their voxels and keypoints (60 B per point), MiB; "
                 "0 = none kept")
      ->envname("K4REG_PAIR_CACHE_MB")
      ->capture_default_str();
  app.add_option("--peer-in-flight", c.peer_in_flight, "pairs of one project out to the peers at once")
      ->envname("K4REG_PEER_IN_FLIGHT")
      ->capture_default_str()
      ->check(CLI::Range(1, 1024));
  app.add_option("--peer-timeout-s", c.peer_timeout_s, "deadline of one pair call to a peer; then it is retried")
      ->envname("K4REG_PEER_TIMEOUT_S")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--peer-token", c.peer_token,
                 "bearer token of pair jobs between replicas: sent with them and required of them (a client's "
                 "--auth-token then cannot submit them); empty = --auth-token")
      ->envname("K4REG_PEER_TOKEN");
  app.add_option("--job-threads", c.job_threads, "core threads per job (caps the request's params.threads)")
      ->envname("K4REG_JOB_THREADS")
      ->capture_default_str()
      ->check(CLI::Range(1, 1024));
  app.add_option("--max-points", c.max_points, "points per cloud, 0 = unlimited")
      ->envname("K4REG_MAX_POINTS")
      ->capture_default_str();
  app.add_option("--max-project-scans", c.max_project_scans, "scans per project request (each may be an upload)")
      ->envname("K4REG_MAX_PROJECT_SCANS")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--max-project-points", c.max_project_points,
                 "points per project, all scans together, as their headers declare them")
      ->envname("K4REG_MAX_PROJECT_POINTS")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--memory-budget-mb", c.memory_budget_mb,
                 "estimated memory of all running jobs (60 bytes per input point), 0 = half the RAM")
      ->envname("K4REG_MEMORY_BUDGET_MB");
  app.add_option("--grpc-receive-quota-mb", c.grpc_receive_quota_mb,
                 "bytes all gRPC calls may be receiving at once, before any token is checked (beyond: "
                 "RESOURCE_EXHAUSTED), MiB; at least the largest message; 0 = half of --memory-budget-mb (64 at least)")
      ->envname("K4REG_GRPC_RECEIVE_QUOTA_MB");
  app.add_option("--spool-dir", c.spool_dir, "parent folder of the upload spool (default: system temp)")
      ->envname("K4REG_SPOOL_DIR");
  app.add_option("--drain-grace-s", c.drain_grace_s, "on SIGTERM, seconds running jobs may take before cancellation")
      ->envname("K4REG_DRAIN_GRACE_S")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--auth-token", c.auth_token, "require 'authorization: Bearer TOKEN' (health stays open)")
      ->envname("K4REG_AUTH_TOKEN");
  app.add_flag("--public-metrics", c.public_metrics,
               "serve HTTP /metrics and /v1/version without the token (otherwise they need it where one is set)")
      ->envname("K4REG_PUBLIC_METRICS");
  app.add_flag("--reflection", c.reflection, "enable gRPC server reflection (off: the API is in the .proto files)")
      ->envname("K4REG_REFLECTION");
  auto* cert = app.add_option("--tls-cert", c.tls_cert, "PEM certificate chain (enables TLS on gRPC and HTTP)")
                   ->envname("K4REG_TLS_CERT")
                   ->check(CLI::ExistingFile);
  auto* key = app.add_option("--tls-key", c.tls_key, "PEM private key")->envname("K4REG_TLS_KEY")->check(CLI::ExistingFile);
  cert->needs(key);
  key->needs(cert);
  app.add_option("--tls-client-ca", c.tls_client_ca,
                 "PEM CA certificates: gRPC and HTTP clients must present a certificate they signed (mutual TLS)")
      ->envname("K4REG_TLS_CLIENT_CA")
      ->check(CLI::ExistingFile)
      ->needs(cert);
  app.add_option("--max-upload-mb", c.max_upload_mb, "largest streamed file, MiB")
      ->envname("K4REG_MAX_UPLOAD_MB")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--max-spool-files", c.max_spool_files,
                 "uploaded files held at once, all calls together (each declared upload holds one until its call ends)")
      ->envname("K4REG_MAX_SPOOL_FILES")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--upload-idle-timeout-s", c.upload_idle_timeout_s,
                 "end an upload call (RegisterStream, RegisterProjectStream) that sends no message this long")
      ->envname("K4REG_UPLOAD_IDLE_TIMEOUT_S")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--max-inline-mb", c.max_inline_mb, "largest unary request (inline clouds), MiB")
      ->envname("K4REG_MAX_INLINE_MB")
      ->capture_default_str()
      ->check(CLI::Range(1, 1024));
  app.add_option("--max-pair-mb", c.max_pair_mb,
                 "largest pair job a peer sends (RegisterPair: two clouds inline, 16 B per point), MiB; the same on "
                 "every replica: a coordinator registers larger pairs itself")
      ->envname("K4REG_MAX_PAIR_MB")
      ->capture_default_str()
      ->check(CLI::Range(0.1, 2000.0));
  app.add_option("--max-connection-age-s", c.max_connection_age_s,
                 "close connections after about this long so clients rebalance across replicas, 0 = never")
      ->envname("K4REG_MAX_CONNECTION_AGE_S")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--max-connection-age-grace-s", c.max_connection_age_grace_s,
                 "time calls on an aged connection get to finish (longer than the longest job)")
      ->envname("K4REG_MAX_CONNECTION_AGE_GRACE_S")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--keepalive-time-s", c.keepalive_time_s, "ping idle connections this often")
      ->envname("K4REG_KEEPALIVE_TIME_S")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--server-id", c.server_id, "replica name returned in every response (default host:pid)")
      ->envname("K4REG_SERVER_ID");
  app.add_option("--log-level", c.log_level, "trace, debug, info, warn, error, critical, off")
      ->envname("K4REG_LOG_LEVEL")
      ->capture_default_str()
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));
}

void finish_config(ServerConfig& c) {
  if (c.workers == 0) c.workers = std::max(1u, std::thread::hardware_concurrency());
  if (c.memory_budget_mb == 0) {
    const long pages = sysconf(_SC_PHYS_PAGES), page_size = sysconf(_SC_PAGE_SIZE);
    c.memory_budget_mb = pages > 0 && page_size > 0 ? std::size_t(pages) * std::size_t(page_size) / 2 / (1 << 20) : 4096;
  }
  if (c.spool_dir.empty()) c.spool_dir = std::filesystem::temp_directory_path().string();
  if (c.server_id.empty()) {
    char host[256] = {};
    gethostname(host, sizeof host - 1);
    c.server_id = std::string(host) + ":" + std::to_string(getpid());
  }
  if (c.grpc_receive_quota_mb == 0) {
    // A message over half the budget would carry a job over the budget anyway (a pair's 16 bytes per point, a
    // binary PLY's 12, become 60 in a job).
    c.grpc_receive_quota_mb = std::max<std::size_t>(c.memory_budget_mb / 2, 64);
  } else if (static_cast<double>(c.grpc_receive_quota_mb) < std::max(static_cast<double>(c.max_inline_mb), c.max_pair_mb) + 1) {
    throw CLI::ValidationError("--grpc-receive-quota-mb",
                               fmt::format("must hold the largest message (--max-inline-mb {}, --max-pair-mb {:g}) and "
                                           "1 MiB more",
                                           c.max_inline_mb, c.max_pair_mb));
  }
  if (c.queue_size == 0) throw CLI::ValidationError("--queue-size", "must be at least 1");
  if (c.pair_workers == 0) c.pair_workers = c.workers;
  if (c.pair_queue_size == 0) throw CLI::ValidationError("--pair-queue-size", "must be at least 1");
}

nlohmann::json config_to_json(const ServerConfig& c) {
  return {{"grpc_listen", c.grpc_listen},
          {"http_listen", c.http_listen},
          {"health_listen", c.health_listen},
          {"port_file", c.port_file},
          {"http_port_file", c.http_port_file},
          {"data_roots", c.data_roots},
          {"workers", c.workers},
          {"queue_size", c.queue_size},
          {"peers", c.peers},
          {"pair_workers", c.pair_workers},
          {"pair_queue_size", c.pair_queue_size},
          {"peer_in_flight", c.peer_in_flight},
          {"peer_timeout_s", c.peer_timeout_s},
          {"peer_auth", !c.peer_token.empty()},
          {"pair_cache_mb", c.pair_cache_mb},
          {"max_pair_mb", c.max_pair_mb},
          {"job_threads", c.job_threads},
          {"max_points", c.max_points},
          {"max_project_scans", c.max_project_scans},
          {"max_project_points", c.max_project_points},
          {"memory_budget_mb", c.memory_budget_mb},
          {"grpc_receive_quota_mb", c.grpc_receive_quota_mb},
          {"spool_dir", c.spool_dir},
          {"drain_grace_s", c.drain_grace_s},
          {"auth", !c.auth_token.empty()},
          {"public_metrics", c.public_metrics},
          {"reflection", c.reflection},
          {"tls", !c.tls_cert.empty()},
          {"tls_client_ca", c.tls_client_ca},
          {"max_upload_mb", c.max_upload_mb},
          {"max_spool_files", c.max_spool_files},
          {"upload_idle_timeout_s", c.upload_idle_timeout_s},
          {"max_inline_mb", c.max_inline_mb},
          {"max_connection_age_s", c.max_connection_age_s},
          {"max_connection_age_grace_s", c.max_connection_age_grace_s},
          {"keepalive_time_s", c.keepalive_time_s},
          {"server_id", c.server_id},
          {"log_level", c.log_level}};
}

}  // namespace k4reg::service
