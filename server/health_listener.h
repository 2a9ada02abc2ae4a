// --health-listen: a plaintext listener that answers health and nothing else, whatever the TLS setting of the
// API listeners, for probes that cannot present or verify a certificate (Kubernetes' gRPC probes, the image's
// HEALTHCHECK). One port, two protocols: a connection that opens with the HTTP/2 preface goes to a gRPC
// server holding only the standard health service (fed the main server's statuses by HealthPublisher);
// anything else is read as one HTTP/1.1 request, of which GET (or HEAD) /healthz and /readyz are answered by
// the HTTP API's own probe routes and everything else gets 404; then the connection closes.
//
// Connections are classified, and HTTP ones answered, one at a time on the listener's thread with 2-second
// socket timeouts: probes are rare and small, and a stalled client only delays the next probe.
#pragma once

#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>

#include <atomic>
#include <memory>
#include <string>
#include <thread>

#include "service_context.h"

namespace k4reg::service {

class HealthListener {
 public:
  // Binds `listen` (host:port, port 0 = ephemeral) and builds the gRPC health server. Call after
  // grpc::EnableDefaultHealthCheckService(true) and before the server reflection plugin is registered:
  // ServerBuilder adds every registered plugin to the servers built afterwards. Throws std::runtime_error.
  HealthListener(const ServiceContext& service, const std::string& listen);
  ~HealthListener();  // stop()
  HealthListener(const HealthListener&) = delete;
  HealthListener& operator=(const HealthListener&) = delete;

  int port() const { return port_; }
  grpc::HealthCheckServiceInterface& health() { return *grpc_->GetHealthCheckService(); }
  // Accepts on a thread of its own.
  void start();
  // Stops accepting and shuts the gRPC health server down. Idempotent.
  void stop();

 private:
  void accept_loop();
  void answer_http(int connection);

  const ServiceContext& service_;
  std::unique_ptr<grpc::Server> grpc_;
  int listen_fd_ = -1, wake_fd_ = -1;  // wake_fd_: an eventfd that stop() signals
  int port_ = 0;
  std::atomic<bool> stopping_{false};
  std::thread thread_;
};

}  // namespace k4reg::service
