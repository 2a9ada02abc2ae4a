// k4reg-server: the k4reg.v1.Registration gRPC service (see proto/k4reg/v1/registration.proto), with
// grpc.health.v1 health and (with --reflection) server reflection, and the same API over HTTP/JSON with /metrics (http_server.h);
// TLS on both (tls.h); optionally a plaintext health-only listener for probes (health_listener.h).
// Configuration: server_config.h (flags or K4REG_* variables).
//
// SIGTERM / SIGINT drain: readiness goes NOT_SERVING (HTTP /readyz 503), new calls get UNAVAILABLE (HTTP 503),
// queued and running jobs get --drain-grace-s to finish, then the rest are cancelled; the process exits 0.
#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>

#include "rpc/grpc_reflection.h"
#include "observability/health.h"
#include "observability/health_listener.h"
#include "http/http_server.h"
#include "observability/json_log.h"
#include "observability/metrics.h"
#include "peers/peer_channel.h"
#include "rpc/registration_service.h"
#include "server_config.h"
#include "security/tls.h"

namespace k4reg::service {
namespace {

using Clock = std::chrono::steady_clock;

int milliseconds(double seconds) { return static_cast<int>(std::min(seconds * 1000.0, 2.0e9)); }

void set_connection_options(grpc::ServerBuilder& builder, const ServerConfig& config) {
  // The largest message is a peer's pair job (--max-pair-mb); Register and RegisterProject check --max-inline-mb.
  // What grpc++ 1.51 offers per method, measured: nothing. It has one receive limit per server (this one); a
  // service config's maxRequestMessageBytes among the server's channel arguments is not applied to its calls;
  // a handler, and so the token check, runs only once the whole message has arrived; an AuthMetadataProcessor
  // (which could refuse from the metadata) is refused on insecure credentials. So a call without the token may
  // hold up to this limit until its message is parsed.
  const double limit_mb = std::max(static_cast<double>(config.max_inline_mb), config.max_pair_mb);
  builder.SetMaxReceiveMessageSize(static_cast<int>(limit_mb * (1 << 20)) + (64 << 10));
  // What bounds the bytes of all calls together is the resource quota: gRPC's reads draw on it, and under its
  // pressure the transport resets streams (RESOURCE_EXHAUSTED, "RST_STREAM with error code 11") until it is
  // back under (--grpc-receive-quota-mb; by default half the memory budget). Measured (tests/integration/
  // grpc_hostile_clients_test.cpp): 4 unauthenticated 150 MB messages at once took the resident set to 1.2 GB
  // without it; 4 x 100 MB with a budget of 256 MiB peak at 340-390 MiB with it (the quota is soft: reclamation
  // runs after the read, and an admitted message is copied once more while it is parsed). A smaller receive
  // limit alone does not bound it: with 1 MiB and no quota, the 4 x 100 MB still peaked at 405 MiB.
  grpc::ResourceQuota quota("k4reg-receive");  // the builder keeps a reference
  builder.SetResourceQuota(quota.Resize(config.grpc_receive_quota_mb << 20));
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIME_MS, milliseconds(config.keepalive_time_s));
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, 20'000);
  // Clients waiting minutes for a job may ping to keep NATs and proxies open; allow it every 10 s.
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_PERMIT_WITHOUT_CALLS, 1);
  builder.AddChannelArgument(GRPC_ARG_HTTP2_MIN_RECV_PING_INTERVAL_WITHOUT_DATA_MS, 10'000);
  if (config.max_connection_age_s > 0) {
    // GOAWAY after the age (+-10 % jitter): clients reconnect and spread over the current replicas.
    builder.AddChannelArgument(GRPC_ARG_MAX_CONNECTION_AGE_MS, milliseconds(config.max_connection_age_s));
    builder.AddChannelArgument(GRPC_ARG_MAX_CONNECTION_AGE_GRACE_MS, milliseconds(config.max_connection_age_grace_s));
  }
}

// Written via a temporary name, so a reader never sees a partial number.
void write_port_file(const std::string& path, int port) {
  const std::string temporary = path + ".tmp";
  std::ofstream(temporary) << port << "\n";
  std::filesystem::rename(temporary, path);
}

int serve(const ServerConfig& config, const sigset_t& stop_signals) {
  log_json(spdlog::level::info, "starting", {{"version", K4REG_VERSION}, {"config", config_to_json(config)}});
  const std::optional<TlsConfig> tls = load_tls(config);
  const PathPolicy paths(config.data_roots);
  SpoolDir spool(config.spool_dir, config.max_spool_files);
  UploadIdleWatch idle_uploads(config.upload_idle_timeout_s);
  MemoryBudget memory(config.memory_budget_mb << 20);
  JobQueue queue(config.workers, config.queue_size);
  JobQueue pair_queue(config.pair_workers, config.pair_queue_size);
  ScanCache pair_scans(config.pair_cache_mb << 20);
  v1::ServerInfo info;
  info.set_version(K4REG_VERSION);
  info.set_server_id(config.server_id);
  Metrics metrics(K4REG_VERSION);
  const ServiceContext context{queue,
                         pair_queue,
                         pair_scans,
                         memory,
                         paths,
                         spool,
                         idle_uploads,
                         JobLimits{config.max_points, config.job_threads, config.max_project_scans, config.max_project_points},
                         config.auth_token,
                         std::uint64_t(config.max_upload_mb) << 20,
                         std::uint64_t(config.max_inline_mb) << 20,
                         info,
                         metrics,
                         config.peers.empty() ? nullptr : make_peer_channel(config.peers, tls),
                         PeerOptions{.in_flight = config.peer_in_flight,
                                     .max_pair_bytes = static_cast<std::uint64_t>(config.max_pair_mb * (1 << 20)),
                                     .call_timeout_s = config.peer_timeout_s,
                                     .token = config.peer_token},
                         config.public_metrics};
  RegistrationService service(context);
  std::unique_ptr<HttpServer> http;
  if (!config.http_listen.empty()) http = std::make_unique<HttpServer>(context, config.http_listen, tls);

  grpc::EnableDefaultHealthCheckService(true);
  // Before the reflection plugin: the health listener's gRPC server must carry the health service only.
  std::unique_ptr<HealthListener> probes;
  if (!config.health_listen.empty()) probes = std::make_unique<HealthListener>(context, config.health_listen);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();  // links the plugin in; it registers itself
  grpc::ServerBuilder builder;
  if (!config.reflection) builder.SetOption(without_reflection());
  int port = 0;
  builder.AddListeningPort(config.grpc_listen, grpc_credentials(tls), &port);
  builder.RegisterService(&service);
  set_connection_options(builder, config);
  const std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
  if (!server || port == 0) {
    log_json(spdlog::level::critical, "cannot listen", {{"grpc_listen", config.grpc_listen}});
    return 1;
  }
  std::vector<grpc::HealthCheckServiceInterface*> health_services{server->GetHealthCheckService()};
  if (probes) health_services.push_back(&probes->health());
  HealthPublisher health(std::move(health_services), queue);
  queue.set_on_change([&health] { health.update(); });
  health.update();  // changes before the line above
  nlohmann::json serving{{"grpc_port", port},
                         {"server_id", config.server_id},
                         {"tls", tls.has_value()},
                         {"grpc_receive_quota_mb", config.grpc_receive_quota_mb}};
  if (probes) {
    probes->start();
    serving["health_port"] = probes->port();
  }
  if (http) {
    http->start();
    serving["http_port"] = http->port();
    // Before the gRPC port file: whoever waits for that one finds this one written.
    if (!config.http_port_file.empty()) write_port_file(config.http_port_file, http->port());
  }
  // The log line first: whoever waits for the port file finds the line (with the health port) written.
  log_json(spdlog::level::info, "serving", std::move(serving));
  if (!config.port_file.empty()) write_port_file(config.port_file, port);

  int signal_number = 0;
  sigwait(&stop_signals, &signal_number);
  log_json(spdlog::level::info, "draining", {{"signal", signal_number}, {"queued", queue.waiting()}, {"running", queue.running()}});
  health.set_draining();
  queue.stop_accepting();
  pair_queue.stop_accepting();  // a coordinator retries its pairs elsewhere
  const auto grace = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(config.drain_grace_s));
  const auto grace_end = Clock::now() + grace;
  const bool idle = queue.wait_idle(grace_end);
  if (!pair_queue.wait_idle(grace_end) || !idle) {
    log_json(spdlog::level::warn, "drain grace period over, cancelling jobs",
             {{"queued", queue.waiting()}, {"running", queue.running()}});
    queue.cancel_all();
    pair_queue.cancel_all();
    queue.wait_idle(Clock::now() + std::chrono::seconds(10));  // cancellation takes effect within ~100 ms
    pair_queue.wait_idle(Clock::now() + std::chrono::seconds(10));
  }
  // HTTP answers of the finished jobs go out; bodies still arriving are cut.
  if (http) http->stop();
  // Replies already handed to gRPC get this long to leave; calls without a job (an unfinished upload) are
  // cut. Idle client connections that ignore GOAWAY also hold Shutdown until the deadline.
  server->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(2));
  // Last: probes keep seeing the drain (readiness NOT_SERVING) until the API listeners are gone.
  if (probes) probes->stop();
  queue.stop();
  log_json(spdlog::level::info, "stopped");
  return 0;
}

}  // namespace
}  // namespace k4reg::service

int main(int argc, char** argv) {
  // Before any thread exists: every thread inherits the blocked mask, so the signals reach only the
  // sigwait() in serve() — no work in a signal handler.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGTERM);
  sigaddset(&stop_signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);

  CLI::App app{"k4reg-server: markerless laser-scan registration (K-4PCS) as a gRPC service"};
  k4reg::service::ServerConfig config;
  k4reg::service::add_config_options(app, config);
  try {
    app.parse(argc, argv);
    k4reg::service::finish_config(config);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  k4reg::service::init_json_logging(config.log_level);
  try {
    return k4reg::service::serve(config, stop_signals);
  } catch (const std::exception& e) {
    k4reg::service::log_json(spdlog::level::critical, "fatal", {{"error", e.what()}});
    return 1;
  }
}
