// k4reg-server's HTTP/1.1 listener (cpp-httplib) for the routes of http_routes.h, in the same process and on
// the same ServiceContext (queue, limits, metrics, access log) as the gRPC service.
//
// Threads: cpp-httplib serves each connection on one thread of a fixed pool, and a registration holds its
// thread while its job waits and runs. The pool has a thread for every job the queue can admit (workers +
// --queue-size) plus spares for probes, metrics, quick refusals and slow clients; further connections wait for
// a thread. A plaintext request's head is bounded in size, field count and time (http_connection.h), its body
// by the routes' limits (the payload limit is the largest of them), each pause by the read timeout.
#pragma once

#include "http/http_lib.h"

#include <atomic>
#include <exception>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "http/http_routes.h"
#include "service_context.h"
#include "security/tls.h"

namespace k4reg::service {

class HttpServer {
 public:
  // Binds `listen`: "host:port", port 0 = ephemeral, "[::]:8080" for IPv6; HTTPS with `tls`. Throws
  // std::runtime_error.
  HttpServer(const ServiceContext& service, const std::string& listen, const std::optional<TlsConfig>& tls);
  ~HttpServer();  // stop()
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  int port() const { return port_; }
  // Serves on a thread of its own; returns once the listener runs.
  void start();
  // Stops listening, interrupts request bodies still arriving (their connections close), and returns once
  // every request being answered has its answer; call after the jobs have ended (JobQueue::wait_idle).
  // Idempotent.
  void stop();

 private:
  void dispatch(const HttpRoute& route, const httplib::Request& request, httplib::Response& response,
                const httplib::ContentReader* content);
  // Unknown paths (404) and other methods on known paths (405), with or without a body.
  void unmatched(const httplib::Request& request, httplib::Response& response, const httplib::ContentReader* content);
  // "Expect: 100-continue": refuses what the headers already tell (401, 404, 413, 503, ...) before the client
  // sends the body.
  int expect_continue(const httplib::Request& request, httplib::Response& response);
  // Answers cpp-httplib produced itself (malformed request line or headers, a head over the listener's
  // budget): the same JSON errors and log.
  httplib::Server::HandlerResponse protocol_error(const httplib::Request& request, httplib::Response& response);
  // The served methods and the same-origin rule (http_access.h): checked before any route and any body, and
  // before "100 Continue".
  grpc::Status head_refusal(const httplib::Request& request) const;
  httplib::Server::HandlerResponse pre_route(const httplib::Request& request, httplib::Response& response);
  // What escaped a handler: a JSON 500 (or the error's own status), and the connection closes.
  void exception(const httplib::Request& request, httplib::Response& response, std::exception_ptr error);

  const ServiceContext& service_;
  std::atomic<bool> stopping_{false};
  std::unique_ptr<httplib::Server> server_;  // an httplib::SSLServer with TLS
  int port_ = 0;
  std::thread thread_;
};

}  // namespace k4reg::service
