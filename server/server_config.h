// Server configuration: command-line flags, each with an environment-variable equivalent (K4REG_*),
// so containers can be configured either way. A flag given on the command line wins over the variable.
#pragma once

#include <CLI/CLI.hpp>
#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace k4reg::service {

struct ServerConfig {
  std::string grpc_listen = "0.0.0.0:50051";  // port 0 = ephemeral (logged and written to port_file)
  std::string http_listen = "0.0.0.0:8080";   // HTTP/JSON API; port 0 = ephemeral, "" = no HTTP listener
  std::string port_file;                      // where to write the bound gRPC port, if set
  std::string http_port_file;                 // where to write the bound HTTP port, if set
  std::vector<std::string> data_roots;        // referenced files must lie under one of these
  std::size_t workers = 0;                    // 0 = number of cores
  std::size_t queue_size = 16;                // waiting jobs beyond the running ones
  std::string peers;                          // gRPC target of the replicas project pairs go to; "" = in process
  std::size_t pair_workers = 0;               // RegisterPair jobs at once (peers' pairs); 0 = workers
  std::size_t pair_queue_size = 16;           // RegisterPair jobs waiting; beyond: RESOURCE_EXHAUSTED (backpressure)
  int peer_in_flight = 4;                     // a coordinated project's pairs out at once
  double peer_timeout_s = 900;                // deadline of one pair call to a peer
  std::string peer_token;                     // if set, pair jobs (RegisterPair) need it instead of --auth-token
  std::size_t pair_cache_mb = 512;            // scans of peers' pair jobs kept, with their preparation
  int job_threads = 1;                        // core threads per job; parallelism comes from the workers
  std::size_t max_points = 50'000'000;        // per cloud; 0 = unlimited
  std::size_t max_project_scans = 500;         // scans (and so uploads) per project request
  std::uint64_t max_project_points = 500'000'000;  // points per project, as the scans' headers declare them
  std::size_t memory_budget_mb = 0;           // for all running jobs; 0 = half the physical memory
  std::size_t grpc_receive_quota_mb = 0;      // bytes all gRPC calls may be receiving at once; 0 = half the budget
  std::string spool_dir;                      // parent of the per-process upload directory; "" = system temp
  double drain_grace_s = 25.0;                // after SIGTERM, running jobs get this long before cancellation
  std::string auth_token;                     // if set, calls need "authorization: Bearer <token>"
  bool public_metrics = false;                // /metrics and /v1/version open without the token
  bool reflection = false;                    // gRPC server reflection (lists the API to anyone who asks)
  std::string tls_cert, tls_key;              // PEM files; both or neither; for gRPC and HTTP
  std::string tls_client_ca;                  // PEM CA file: clients must present a certificate it signed
  std::string health_listen;                  // plaintext health-only listener; "" = none
  std::size_t max_upload_mb = 4096;           // per streamed file
  std::size_t max_spool_files = 1000;         // uploads in flight on the server, all calls together
  double upload_idle_timeout_s = 60;          // an upload call that sends nothing this long is ended
  std::size_t max_inline_mb = 32;             // per Register / RegisterProject request (inline clouds)
  double max_pair_mb = 1024;                  // per RegisterPair request (a peer's pair job); gRPC's message limit
  double max_connection_age_s = 0;            // 0 = unlimited; otherwise GOAWAY after ~this long (rebalancing)
  double max_connection_age_grace_s = 600;    // calls in flight on an aged connection get this long to end
  double keepalive_time_s = 60;               // server pings idle connections this often
  std::string server_id;                      // "" = host:pid
  std::string log_level = "info";
};

void add_config_options(CLI::App& app, ServerConfig& config);
// Fills the derived defaults (workers, memory budget, spool dir, server id) and checks combinations.
// Throws CLI::ValidationError.
void finish_config(ServerConfig& config);
// For the start-up log line: everything except the token's value.
nlohmann::json config_to_json(const ServerConfig& config);

}  // namespace k4reg::service
