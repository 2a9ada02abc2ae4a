// How the remote commands reach the service: the --server target (one address, a round-robin list, or any
// gRPC target), TLS, the bearer token, and the per-call metadata.
#pragma once

#include <grpcpp/grpcpp.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <memory>
#include <string>

namespace k4reg::cli {

struct ConnectionOptions {
  std::string server;  // host:port, a comma list of IP:port (round robin), or a gRPC target (dns:///name:port)
  bool tls = false;
  std::string ca_cert;  // PEM roots; implies TLS. Without it, TLS uses the system's roots.
  std::string token;    // --token or $K4REG_TOKEN: sent as "authorization: Bearer <token>"
};

// --server (required; $K4REG_SERVER), --tls ($K4REG_TLS), --ca-cert ($K4REG_CA_CERT), --token ($K4REG_TOKEN).
void add_connection_flags(CLI::App& command, ConnectionOptions& options);

// The gRPC target for --server: "host:port" and "dns:///..."-style targets pass through; a comma list
// "10.0.0.1:50051,10.0.0.2:50051" becomes "ipv4:10.0.0.1:50051,10.0.0.2:50051" (gRPC's static resolver,
// which takes IP literals only). Throws std::invalid_argument for malformed input.
std::string channel_target(const std::string& server);

// One channel per command with the round_robin policy, so calls spread over every address of the target
// (the list, or all addresses a DNS name resolves to) instead of sticking to the first.
// The largest reply a channel receives: a preview of kMaxPreviewPoints (32 MB) with room for the rest.
inline constexpr int kMaxReplyBytes = 64 << 20;

std::shared_ptr<grpc::Channel> make_channel(const ConnectionOptions& options);

// Token and request id metadata; `request_id` may be empty (the server then generates one).
void add_call_metadata(grpc::ClientContext& context, const ConnectionOptions& options, const std::string& request_id);

// now + seconds, as ClientContext::set_deadline takes it.
std::chrono::system_clock::time_point deadline_after(double seconds);

// A random UUID (version 4) for x-request-id, so a call can be found in the server's log.
std::string new_request_id();

}  // namespace k4reg::cli
