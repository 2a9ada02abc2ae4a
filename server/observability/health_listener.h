// --health-listen: a plaintext listener that answers health and nothing else, whatever the TLS setting of the
// API listeners, for probes that cannot present or verify a certificate (Kubernetes' gRPC probes, the image's
// HEALTHCHECK). One port, two protocols: a connection that opens with the HTTP/2 preface goes to a gRPC
// server holding only the standard health service (fed the main server's statuses by HealthPublisher);
// anything else is read as one HTTP/1.1 request (health_request.h), of which GET (or HEAD) /healthz and /readyz
// are answered by the HTTP API's own probe routes, other methods on them get 405, other paths 404, a malformed
// head 400 and an oversized one 414 or 431; then the connection closes.
//
// No client can keep a probe waiting: each connection is served on a thread of its own and has
// kRequestDeadline from accept to its whole request head (the HTTP/2 preface, for gRPC), however slowly the
// bytes drip in. At most kMaxConnections are served at once; one more evicts the oldest, so that idle
// connections cannot lock a probe out. Whatever a connection's handling throws closes that connection only,
// and is logged.
#pragma once

#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

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
  // A probe sends its request in one packet and is answered within milliseconds: the deadline leaves a wide
  // margin, and the cap bounds the threads that a flood of connections holds.
  static constexpr auto kRequestDeadline = std::chrono::seconds(2);
  static constexpr std::size_t kMaxConnections = 64;

  // Accepts on a thread of its own.
  void start();
  // Stops accepting, ends the connections being served and shuts the gRPC health server down. Idempotent.
  void stop();

 private:
  using Clock = std::chrono::steady_clock;
  void accept_loop();
  // Adds `connection` to those served, evicting the oldest beyond kMaxConnections.
  void admit(int connection);
  // Out of connections_ (if eviction has not taken it out already): nothing shuts it down from then on.
  void forget(int connection);
  void thread_ended();
  // On the connection's own thread: the gRPC handover, or the HTTP answer and the socket closed. Catches
  // everything: a failure costs this connection only.
  void serve(int connection);
  // False when there is nothing to answer (the client went away or missed the deadline).
  bool answer_http(int connection, Clock::time_point deadline);

  const ServiceContext& service_;
  std::unique_ptr<grpc::Server> grpc_;
  int listen_fd_ = -1, wake_fd_ = -1;  // wake_fd_: an eventfd that stop() signals
  int port_ = 0;
  std::atomic<bool> stopping_{false};
  std::thread thread_;
  std::mutex connections_mutex_;
  std::condition_variable connection_threads_done_;
  std::vector<int> connections_;  // being served, oldest first: what eviction and stop() shut down
  std::size_t connection_threads_ = 0;  // evicted connections' threads count until they end
};

}  // namespace k4reg::service
