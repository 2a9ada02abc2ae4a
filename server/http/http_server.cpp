#include "http/http_server.h"

#include <chrono>
#include <stdexcept>

#include "security/http_access.h"
#include "http/http_connection.h"
#include "http/http_register.h"
#include "http/listen_address.h"
#include "api/status_mapping.h"

namespace k4reg::service {
namespace {

// Threads beyond one per admissible job: probes, metrics and refusals must get through a busy server, and
// clients that dawdle over their heads (each held at most kHeadDeadline) or bodies must not take every thread.
// An idle thread costs its stack's touched pages only.
constexpr std::size_t kSpareThreads = 64;
// Idle keep-alive connections hold a thread this long, and stop() may wait for them as long.
constexpr time_t kKeepAliveTimeoutS = 2;
// A client may pause this long while sending a body.
constexpr time_t kReadTimeoutS = 15;
// A client that reads no answer (or no event of a stream) for this long loses its connection.
constexpr time_t kWriteTimeoutS = 15;
constexpr const char* kUnmatchedRoute = "unmatched";

std::string regex_escaped(std::string_view literal) {
  std::string pattern;
  for (const char c : literal) {
    if (std::string_view(".^$|()[]{}*+?\\").find(c) != std::string_view::npos) pattern += '\\';
    pattern += c;
  }
  return pattern;
}

const HttpRoute* find_route(const std::string& method, const std::string& path) {
  for (const HttpRoute& route : http_routes())
    if (route.path == path && (route.method == method || (method == "HEAD" && route.method == "GET"))) return &route;
  return nullptr;
}

// NOT_FOUND for an unknown path, UNIMPLEMENTED (405) with the allowed methods for a known one.
grpc::Status unmatched_status(const httplib::Request& request, std::string& allowed) {
  for (const HttpRoute& route : http_routes())
    if (route.path == request.path) allowed += (allowed.empty() ? "" : ", ") + std::string(route.method);
  if (allowed.empty())
    return {grpc::StatusCode::NOT_FOUND, "no route " + request.path + " (the API is described at /openapi.json)"};
  return {grpc::StatusCode::UNIMPLEMENTED, request.method + " is not allowed on " + request.path + " (" + allowed + ")"};
}

// HTTPS with the gRPC listener's certificate and client verification when TLS is on (tls.h). Plaintext
// connections are BoundedHttpServer's; TLS ones cpp-httplib's own (their heads bounded by its read timeout only).
std::unique_ptr<httplib::Server> make_server(const std::optional<TlsConfig>& tls) {
  if (!tls) return std::make_unique<BoundedHttpServer>();
  // No exception may leave the callback (cpp-httplib would leak its context); load_tls ran the same checks.
  auto server = std::make_unique<httplib::SSLServer>([&tls](SSL_CTX& context) {
    try {
      configure_ssl_context(context, *tls);
      return true;
    } catch (const std::runtime_error&) {
      return false;
    }
  });
  if (!server->is_valid()) throw std::runtime_error("cannot set up TLS for --http-listen");
  return server;
}

}  // namespace

HttpServer::HttpServer(const ServiceContext& service, const std::string& listen, const std::optional<TlsConfig>& tls)
    : service_(service), server_(make_server(tls)) {
  const std::size_t threads = service.queue.workers() + service.queue.capacity() + kSpareThreads;
  server_->new_task_queue = [threads] { return new httplib::ThreadPool(threads); };
  server_->set_keep_alive_timeout(kKeepAliveTimeoutS);
  server_->set_keep_alive_max_count(100);
  server_->set_read_timeout(kReadTimeoutS);
  server_->set_write_timeout(kWriteTimeoutS);
  // cpp-httplib's own limit, for bodies it would read itself: the largest any route takes.
  server_->set_payload_max_length(largest_body_limit(service));
  server_->set_default_headers(default_security_headers());
  server_->set_pre_routing_handler(
      [this](const httplib::Request& request, httplib::Response& response) { return pre_route(request, response); });
  server_->set_exception_handler([this](const httplib::Request& request, httplib::Response& response,
                                        std::exception_ptr error) { exception(request, response, error); });
  for (const HttpRoute& route : http_routes()) {
    const std::string pattern = regex_escaped(route.path);
    if (route.method == "GET")
      server_->Get(pattern, [this, &route](const httplib::Request& request, httplib::Response& response) {
        dispatch(route, request, response, nullptr);
      });
    else
      server_->Post(pattern, [this, &route](const httplib::Request& request, httplib::Response& response,
                                           const httplib::ContentReader& content) {
        dispatch(route, request, response, &content);
      });
  }
  // Registered last, so they see only what no route took.
  const auto without_body = [this](const httplib::Request& request, httplib::Response& response) {
    unmatched(request, response, nullptr);
  };
  const auto with_body = [this](const httplib::Request& request, httplib::Response& response,
                                const httplib::ContentReader& content) { unmatched(request, response, &content); };
  server_->Get(".*", without_body);
  server_->Options(".*", without_body);
  server_->Post(".*", with_body);
  server_->Put(".*", with_body);
  server_->Patch(".*", with_body);
  server_->Delete(".*", with_body);
  server_->set_expect_100_continue_handler(
      [this](const httplib::Request& request, httplib::Response& response) { return expect_continue(request, response); });
  server_->set_error_handler(httplib::Server::HandlerWithResponse(
      [this](const httplib::Request& request, httplib::Response& response) { return protocol_error(request, response); }));

  const auto [host, port] = parse_listen_address(listen, "--http-listen");
  port_ = port == 0 ? server_->bind_to_any_port(host) : (server_->bind_to_port(host, port) ? port : -1);
  if (port_ <= 0) throw std::runtime_error("cannot listen on " + listen + " (HTTP)");
  if (auto* bounded = dynamic_cast<BoundedHttpServer*>(server_.get())) {
    bounded->widen_backlog();
    bounded->set_head_refusal_handler(
        [this](const httplib::Request& request, httplib::Response& response) { protocol_error(request, response); });
  }
}

HttpServer::~HttpServer() { stop(); }

void HttpServer::start() {
  thread_ = std::thread([this] { server_->listen_after_bind(); });
  // stop() right after start() must find a running server to stop.
  while (!server_->is_running()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
}

void HttpServer::stop() {
  stopping_ = true;
  server_->stop();
  if (thread_.joinable()) thread_.join();  // listen_after_bind returns once its pool has finished every connection
}

void HttpServer::dispatch(const HttpRoute& route, const httplib::Request& request, httplib::Response& response,
                          const httplib::ContentReader* content) {
  HttpExchange exchange(service_, request, response, route_name(route), content, stopping_);
  exchange.record.probe = route.probe;
  try {
    route.handle(service_, exchange);
  } catch (...) {
    exchange.fail(status_from_current_exception());
  }
  exchange.end();
}

void HttpServer::unmatched(const httplib::Request& request, httplib::Response& response,
                           const httplib::ContentReader* content) {
  HttpExchange exchange(service_, request, response, kUnmatchedRoute, content, stopping_);
  std::string allowed;
  exchange.fail(unmatched_status(request, allowed));
  if (!allowed.empty()) response.set_header("Allow", allowed);
  exchange.end();
}

int HttpServer::expect_continue(const httplib::Request& request, httplib::Response& response) {
  const HttpRoute* route = find_route(request.method, request.path);
  std::string allowed;
  grpc::Status status = head_refusal(request);
  if (status.ok())
    status = !route                 ? unmatched_status(request, allowed)
             : route->check_headers ? route->check_headers(service_, request)
                                    : grpc::Status::OK;
  if (status.ok()) return 100;
  HttpExchange exchange(service_, request, response, route ? route_name(*route) : kUnmatchedRoute, nullptr, stopping_);
  exchange.fail(status);
  if (!allowed.empty()) response.set_header("Allow", allowed);
  exchange.end_before_body();
  return response.status;
}

httplib::Server::HandlerResponse HttpServer::protocol_error(const httplib::Request& request,
                                                            httplib::Response& response) {
  if (response.has_header("Content-Type")) return httplib::Server::HandlerResponse::Unhandled;  // a route's answer
  int status = response.status;
  grpc::Status error{status == 413   ? grpc::StatusCode::RESOURCE_EXHAUSTED
                     : status >= 500 ? grpc::StatusCode::INTERNAL
                                     : grpc::StatusCode::INVALID_ARGUMENT,
                     "malformed HTTP request (HTTP status " + std::to_string(status) + ")"};
  // A head over the listener's budget reads to cpp-httplib as a malformed one: the budget says what it was.
  if (const BoundedSocketStream* stream = BoundedSocketStream::current(); stream && !stream->head_refusal().empty()) {
    status = stream->head_refusal_status();
    error = {status == 408 ? grpc::StatusCode::DEADLINE_EXCEEDED : grpc::StatusCode::RESOURCE_EXHAUSTED,
             stream->head_refusal()};
  }
  HttpExchange exchange(service_, request, response, kUnmatchedRoute, nullptr, stopping_);
  exchange.fail(error, status);
  exchange.end_before_body();  // where the next request would start is unknown: the connection closes
  return httplib::Server::HandlerResponse::Handled;
}

grpc::Status HttpServer::head_refusal(const httplib::Request& request) const {
  grpc::Status status = check_method(request);
  if (status.ok()) status = check_same_origin(service_.auth_token, request);
  return status;
}

httplib::Server::HandlerResponse HttpServer::pre_route(const httplib::Request& request, httplib::Response& response) {
  if (BoundedSocketStream* stream = BoundedSocketStream::current()) stream->head_complete();
  const grpc::Status status = head_refusal(request);
  if (status.ok()) return httplib::Server::HandlerResponse::Unhandled;
  const HttpRoute* route = find_route(request.method, request.path);
  HttpExchange exchange(service_, request, response, route ? route_name(*route) : kUnmatchedRoute, nullptr, stopping_);
  exchange.fail(status);
  exchange.end_before_body();
  return httplib::Server::HandlerResponse::Handled;
}

void HttpServer::exception(const httplib::Request& request, httplib::Response& response, std::exception_ptr error) {
  HttpExchange exchange(service_, request, response, kUnmatchedRoute, nullptr, stopping_);
  try {
    std::rethrow_exception(error);
  } catch (...) {
    exchange.fail(status_from_current_exception());
  }
  exchange.end_before_body();  // where the body stands is unknown: the connection closes
}

}  // namespace k4reg::service
