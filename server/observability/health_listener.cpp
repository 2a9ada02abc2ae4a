#include "observability/health_listener.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <grpcpp/server_posix.h>
#include <netdb.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string_view>
#include <system_error>

#include "observability/health_request.h"
#include "http/http_exchange.h"
#include "http/http_routes.h"
#include "observability/json_log.h"
#include "http/listen_address.h"

namespace k4reg::service {
namespace {

using Clock = std::chrono::steady_clock;

constexpr std::string_view kHttp2Preface = "PRI * HTTP/2.0";
constexpr timeval kSendTimeout{2, 0};  // an answer is under a kilobyte: it fits the socket's buffer at once
constexpr const char* kUnmatchedRoute = "unmatched";

int bind_socket(const ListenAddress& address, const std::string& listen) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
  addrinfo* found = nullptr;
  const std::string port = std::to_string(address.port);
  if (getaddrinfo(address.host.c_str(), port.c_str(), &hints, &found) != 0 || !found)
    throw std::runtime_error("--health-listen " + listen + ": cannot resolve the host");
  const std::unique_ptr<addrinfo, decltype(&freeaddrinfo)> owner(found, freeaddrinfo);
  const int fd = socket(found->ai_family, SOCK_STREAM | SOCK_CLOEXEC, 0);
  const int yes = 1;
  // A long backlog: a burst of connections waits for accept rather than being dropped (a dropped SYN is
  // retried after a second, longer than a probe's timeout).
  if (fd < 0 || setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes) != 0 ||
      bind(fd, found->ai_addr, found->ai_addrlen) != 0 || ::listen(fd, SOMAXCONN) != 0) {
    const std::string reason = std::strerror(errno);
    if (fd >= 0) close(fd);
    throw std::runtime_error("cannot listen on " + listen + " (health): " + reason);
  }
  return fd;
}

int bound_port(int fd) {
  sockaddr_storage address{};
  socklen_t size = sizeof address;
  getsockname(fd, reinterpret_cast<sockaddr*>(&address), &size);
  return ntohs(address.ss_family == AF_INET6 ? reinterpret_cast<sockaddr_in6&>(address).sin6_port
                                             : reinterpret_cast<sockaddr_in&>(address).sin_port);
}

// Receives wait at most until `deadline`; false once it has passed (a zero SO_RCVTIMEO would mean no limit).
bool receive_until(int fd, Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::microseconds>(deadline - Clock::now()).count();
  if (left <= 0) return false;
  const timeval timeout{static_cast<time_t>(left / 1'000'000), static_cast<suseconds_t>(left % 1'000'000)};
  return setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout) == 0;
}

// Peeked, not read: gRPC reads the preface again.
bool opens_with_http2_preface(int fd, Clock::time_point deadline) {
  std::array<char, kHttp2Preface.size()> start{};
  if (!receive_until(fd, deadline)) return false;
  ssize_t got = recv(fd, start.data(), start.size(), MSG_PEEK);
  // The preface's first bytes only: wait for the rest of it (an HTTP/1.1 head differs within them).
  if (got > 0 && std::size_t(got) < start.size() && kHttp2Preface.starts_with(std::string_view(start.data(), got)) &&
      receive_until(fd, deadline))
    got = recv(fd, start.data(), start.size(), MSG_PEEK | MSG_WAITALL);
  return got == ssize_t(start.size()) && std::string_view(start.data(), start.size()) == kHttp2Preface;
}

// The peer's address and port, as cpp-httplib fills them in, for the access log.
void fill_peer(int fd, httplib::Request& request) {
  sockaddr_storage address{};
  socklen_t size = sizeof address;
  if (getpeername(fd, reinterpret_cast<sockaddr*>(&address), &size) != 0) return;
  char host[INET6_ADDRSTRLEN] = {};
  char port[8] = {};
  getnameinfo(reinterpret_cast<sockaddr*>(&address), size, host, sizeof host, port, sizeof port,
              NI_NUMERICHOST | NI_NUMERICSERV);
  request.remote_addr = host;
  request.remote_port = std::atoi(port);
}

// Reads until the head is complete or refused; kIncomplete if the client went away or `deadline` came first.
HealthRequestHead read_head(int fd, Clock::time_point deadline) {
  std::string received;
  std::array<char, 1024> buffer;
  HealthRequestHead head;
  while (head.state == HealthRequestHead::State::kIncomplete && receive_until(fd, deadline)) {
    const ssize_t got = recv(fd, buffer.data(), buffer.size(), 0);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) break;
    received.append(buffer.data(), std::size_t(got));
    // The outcome changes only when a line ends or the size limit is passed: parsing only then keeps a client
    // that sends a byte at a time from costing quadratic time.
    if (std::memchr(buffer.data(), '\n', std::size_t(got)) || received.size() > kMaxHealthHeadBytes)
      head = parse_health_request(received);
  }
  return head;
}

// The probe route at `path`, whatever the method; null for any other path.
const HttpRoute* find_probe(std::string_view path) {
  for (const HttpRoute& route : http_routes())
    if ((route.path == "/healthz" || route.path == "/readyz") && route.path == path) return &route;
  return nullptr;
}

std::string_view reason_phrase(int status) {
  switch (status) {
    case 200: return "OK";
    case 400: return "Bad Request";
    case 404: return "Not Found";
    case 405: return "Method Not Allowed";
    case 414: return "URI Too Long";
    case 431: return "Request Header Fields Too Large";
    case 503: return "Service Unavailable";
    default: return "";  // optional in HTTP/1.1 (RFC 9112, 4)
  }
}

// Closing a socket with unread request bytes (a body this listener does not want) resets the connection, and the
// reset can destroy the answer before the client reads it. So: finish sending, then read what the client still
// sends, for at most a second and kMaxDrainBytes, before the socket is closed.
void drain_after_answer(int fd) {
  constexpr std::size_t kMaxDrainBytes = 16 << 20;
  shutdown(fd, SHUT_WR);
  const auto deadline = Clock::now() + std::chrono::seconds(1);
  const timeval wait{0, 100'000};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &wait, sizeof wait);
  std::array<char, 16384> sink;
  for (std::size_t drained = 0; drained < kMaxDrainBytes && Clock::now() < deadline;) {
    const ssize_t got = recv(fd, sink.data(), sink.size(), 0);
    if (got == 0 || (got < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) break;
    if (got > 0) drained += std::size_t(got);
  }
}

void send_all(int fd, const std::string& bytes) {
  for (std::size_t sent = 0; sent < bytes.size();) {
    const ssize_t done = send(fd, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (done <= 0) return;
    sent += std::size_t(done);
  }
}

}  // namespace

HealthListener::HealthListener(const ServiceContext& service, const std::string& listen) : service_(service) {
  // No listening port: connections are handed over one by one (AddInsecureChannelFromFd).
  grpc::ServerBuilder builder;
  grpc_ = builder.BuildAndStart();
  if (!grpc_ || !grpc_->GetHealthCheckService()) throw std::runtime_error("cannot start the gRPC health server");
  listen_fd_ = bind_socket(parse_listen_address(listen, "--health-listen"), listen);
  port_ = bound_port(listen_fd_);
  wake_fd_ = eventfd(0, EFD_CLOEXEC);
  if (wake_fd_ < 0) throw std::runtime_error("eventfd: " + std::string(std::strerror(errno)));
}

HealthListener::~HealthListener() {
  stop();
  close(listen_fd_);
  close(wake_fd_);
}

void HealthListener::start() { thread_ = std::thread([this] { accept_loop(); }); }

void HealthListener::stop() {
  if (stopping_.exchange(true)) return;
  eventfd_write(wake_fd_, 1);
  if (thread_.joinable()) thread_.join();
  {
    std::unique_lock lock(connections_mutex_);
    for (const int connection : connections_) shutdown(connection, SHUT_RDWR);  // their threads end at once
    connection_threads_done_.wait(lock, [this] { return connection_threads_ == 0; });
  }
  grpc_->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(1));
}

void HealthListener::accept_loop() {
  std::array<pollfd, 2> waiting{pollfd{listen_fd_, POLLIN, 0}, pollfd{wake_fd_, POLLIN, 0}};
  while (!stopping_) {
    if (poll(waiting.data(), waiting.size(), -1) < 0 || waiting[1].revents) continue;  // EINTR, or stop()
    const int connection = accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
    if (connection < 0) continue;
    setsockopt(connection, SOL_SOCKET, SO_SNDTIMEO, &kSendTimeout, sizeof kSendTimeout);
    admit(connection);
    try {
      std::thread([this, connection] {
        serve(connection);
        thread_ended();
      }).detach();
    } catch (const std::system_error& e) {  // no thread to be had: this connection goes unanswered
      log_json(spdlog::level::err, "health connection failed", {{"error", e.what()}});
      forget(connection);
      close(connection);
      thread_ended();
    }
  }
}

void HealthListener::admit(int connection) {
  bool evicted = false;
  {
    std::lock_guard lock(connections_mutex_);
    if (connections_.size() == kMaxConnections) {
      // The oldest has had the longest to send its request; a probe sends it at once.
      shutdown(connections_.front(), SHUT_RDWR);
      connections_.erase(connections_.begin());
      evicted = true;
    }
    connections_.push_back(connection);
    ++connection_threads_;
  }
  if (evicted)
    log_json(spdlog::level::warn, "health connection evicted", {{"max_connections", kMaxConnections}});
}

void HealthListener::forget(int connection) {
  std::lock_guard lock(connections_mutex_);
  const auto found = std::find(connections_.begin(), connections_.end(), connection);
  if (found != connections_.end()) connections_.erase(found);
}

void HealthListener::thread_ended() {
  // Notified under the lock: once stop() sees the count reach 0, no connection thread touches this object.
  std::lock_guard lock(connections_mutex_);
  --connection_threads_;
  connection_threads_done_.notify_all();
}

void HealthListener::serve(int connection) {
  const Clock::time_point deadline = Clock::now() + kRequestDeadline;
  try {
    if (opens_with_http2_preface(connection, deadline)) {
      forget(connection);
      fcntl(connection, F_SETFL, fcntl(connection, F_GETFL) | O_NONBLOCK);
      grpc::AddInsecureChannelFromFd(grpc_.get(), connection);  // gRPC owns the socket from here
      return;
    }
    if (answer_http(connection, deadline)) drain_after_answer(connection);
  } catch (const std::exception& e) {
    log_json(spdlog::level::err, "health connection failed", {{"error", e.what()}});
  } catch (...) {
    log_json(spdlog::level::err, "health connection failed", {{"error", "unknown exception"}});
  }
  // Forgotten before it is closed, so that eviction or stop() never shuts down a reused descriptor.
  forget(connection);
  close(connection);
}

bool HealthListener::answer_http(int connection, Clock::time_point deadline) {
  using State = HealthRequestHead::State;
  const HealthRequestHead head = read_head(connection, deadline);
  if (head.state == State::kIncomplete) return false;  // the client went away or stalled: nothing to answer
  httplib::Request request;
  httplib::Response response;
  fill_peer(connection, request);
  request.method = head.method;
  request.path = head.path;
  for (const auto& [name, value] : head.fields) request.headers.emplace(name, value);
  const HttpRoute* probe = head.state == State::kComplete ? find_probe(request.path) : nullptr;
  const bool readable_method = request.method == "GET" || request.method == "HEAD";
  const HttpRoute* route = probe && readable_method ? probe : nullptr;
  HttpExchange exchange(service_, request, response, route ? route_name(*route) : kUnmatchedRoute, nullptr, stopping_);
  exchange.record.probe = true;
  if (route) {
    route->handle(service_, exchange);
  } else if (head.state == State::kRefused) {
    const auto code = head.refusal_status == 400 ? grpc::StatusCode::INVALID_ARGUMENT : grpc::StatusCode::RESOURCE_EXHAUSTED;
    exchange.fail({code, head.refusal}, head.refusal_status);
  } else if (probe) {
    exchange.fail({grpc::StatusCode::UNIMPLEMENTED, "the health listener answers only GET and HEAD"}, 405);
    response.set_header("Allow", "GET, HEAD");
  } else {
    exchange.fail({grpc::StatusCode::NOT_FOUND, "the health listener answers only GET /healthz and GET /readyz"});
  }
  exchange.end();
  std::string answer = "HTTP/1.1 " + std::to_string(response.status) + " " + std::string(reason_phrase(response.status)) + "\r\n";
  for (const auto& [name, value] : response.headers) answer += name + ": " + value + "\r\n";
  answer += "Content-Length: " + std::to_string(response.body.size()) + "\r\nConnection: close\r\n\r\n";
  if (request.method != "HEAD") answer += response.body;
  send_all(connection, answer);
  return true;
}

}  // namespace k4reg::service
