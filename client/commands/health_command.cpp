#include "commands/health_command.h"

#include <cstdlib>
#include <iostream>
#include <memory>

#include "remote/channel.h"
#include "commands/command_error.h"
#include "grpc/health/v1/health.grpc.pb.h"
#include "reports/status_text.h"

namespace k4reg::cli {
namespace {

using grpc::health::v1::HealthCheckRequest;
using grpc::health::v1::HealthCheckResponse;

struct HealthOptions {
  ConnectionOptions connection;
  std::string service;
  CLI::Option* service_flag = nullptr;  // given: check only that name
  double deadline_s = 2;                // a probe must answer quickly; a hung server counts as unhealthy
};

// The server's --health-listen address as seen from its own host: a wildcard host becomes loopback.
std::string local_target(const std::string& listen) {
  const auto colon = listen.rfind(':');
  const std::string host = listen.substr(0, colon == std::string::npos ? 0 : colon);
  const std::string port = colon == std::string::npos ? "" : listen.substr(colon + 1);
  if (port.empty() || port == "0")
    throw CommandError("K4REG_HEALTH_LISTEN=" + listen + " names no fixed port: give --server");
  if (host == "0.0.0.0" || host.empty()) return "127.0.0.1:" + port;
  if (host == "[::]") return "[::1]:" + port;
  return listen;
}

// Without --server and $K4REG_SERVER: the health listener of a server started from the same environment
// ($K4REG_HEALTH_LISTEN, as in the image), in plaintext since that listener never uses TLS. So the image's
// HEALTHCHECK follows the container's settings, TLS or not, whatever the port.
ConnectionOptions resolved(const ConnectionOptions& given) {
  if (!given.server.empty()) return given;
  const char* listen = std::getenv("K4REG_HEALTH_LISTEN");
  if (!listen || !*listen) throw CommandError("no server: give --server, or set K4REG_SERVER or K4REG_HEALTH_LISTEN");
  ConnectionOptions connection = given;
  connection.server = local_target(listen);
  connection.tls = false;
  connection.ca_cert.clear();
  return connection;
}

void run_health(const HealthOptions& options) {
  HealthOptions o = options;
  o.connection = resolved(options.connection);
  const std::shared_ptr<grpc::Channel> channel = make_channel(o.connection);
  auto stub = grpc::health::v1::Health::NewStub(channel);
  const std::vector<std::string> services = o.service_flag->count() > 0
                                                ? std::vector<std::string>{o.service}
                                                : std::vector<std::string>{"liveness", "readiness"};
  bool all_serving = true;
  for (const std::string& service : services) {
    grpc::ClientContext context;
    add_call_metadata(context, o.connection, "");
    context.set_deadline(deadline_after(o.deadline_s));
    HealthCheckRequest request;
    request.set_service(service);
    HealthCheckResponse reply;
    const grpc::Status status = stub->Check(&context, request, &reply);
    if (!status.ok()) throw CommandError(describe_failure(status, *channel, o.connection.server));
    std::cout << (service.empty() ? "\"\"" : service) << ": " << HealthCheckResponse::ServingStatus_Name(reply.status())
              << "\n";
    all_serving = all_serving && reply.status() == HealthCheckResponse::SERVING;
  }
  if (!all_serving) throw CLI::RuntimeError(1);  // exit code 1, nothing more to print
}

}  // namespace

void add_health_command(CLI::App& app) {
  auto options = std::make_shared<HealthOptions>();
  CLI::App* command = app.add_subcommand(
      "health", "check the server's liveness and readiness; exit code 0 when both are SERVING, 1 otherwise");
  add_connection_flags(*command, options->connection);
  command->get_option("--server")
      ->required(false)
      ->description("HOST:PORT or a gRPC target (as for register); default: $K4REG_SERVER, else the local "
                    "server's plaintext health listener from $K4REG_HEALTH_LISTEN");
  options->service_flag = command->add_option(
      "--service", options->service,
      "check this one name instead (liveness, readiness, k4reg.v1.Registration, \"\" = the server)");
  command->add_option("--deadline", options->deadline_s, "seconds to wait for each answer")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  command->callback([options] { run_health(*options); });
}

}  // namespace k4reg::cli
