#include "health_listener.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <grpcpp/server_posix.h>
#include <netdb.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <stdexcept>
#include <string_view>

#include "http_exchange.h"
#include "http_routes.h"
#include "listen_address.h"

namespace k4reg::service {
namespace {

constexpr std::string_view kHttp2Preface = "PRI * HTTP/2.0";
constexpr int kSocketTimeoutS = 2;
// A probe's request line and headers; anything longer is not a probe.
constexpr std::size_t kMaxRequestBytes = 8 << 10;
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
  if (fd < 0 || setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes) != 0 ||
      bind(fd, found->ai_addr, found->ai_addrlen) != 0 || ::listen(fd, 64) != 0) {
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

void set_timeouts(int fd) {
  const timeval timeout{kSocketTimeoutS, 0};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &timeout, sizeof timeout);
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

// The request line and headers, up to the blank line; false if they do not arrive in time or are too long.
bool read_head(int fd, std::string& head) {
  std::array<char, 1024> buffer;
  while (head.find("\r\n\r\n") == std::string::npos) {
    const ssize_t got = recv(fd, buffer.data(), buffer.size(), 0);
    if (got <= 0 || head.size() + std::size_t(got) > kMaxRequestBytes) return false;
    head.append(buffer.data(), std::size_t(got));
  }
  return true;
}

// "GET /readyz?x HTTP/1.1" and "Name: value" lines; false if the request line is malformed.
bool parse_head(const std::string& head, httplib::Request& request) {
  std::size_t line_end = head.find("\r\n");
  const std::string line = head.substr(0, line_end);
  const auto first = line.find(' '), last = line.rfind(' ');
  if (first == std::string::npos || last == first || line.compare(last + 1, 5, "HTTP/") != 0) return false;
  request.method = line.substr(0, first);
  const std::string target = line.substr(first + 1, last - first - 1);
  request.path = target.substr(0, target.find('?'));
  while (line_end != std::string::npos && line_end + 2 < head.size()) {
    const std::size_t next = head.find("\r\n", line_end + 2);
    const std::string header = head.substr(line_end + 2, next - line_end - 2);
    const auto colon = header.find(':');
    if (colon != std::string::npos)
      request.headers.emplace(header.substr(0, colon), header.substr(header.find_first_not_of(' ', colon + 1)));
    line_end = next;
  }
  return true;
}

// Only the probe routes of the HTTP API.
const HttpRoute* find_probe(const httplib::Request& request) {
  if (request.method != "GET" && request.method != "HEAD") return nullptr;
  for (const HttpRoute& route : http_routes())
    if ((route.path == "/healthz" || route.path == "/readyz") && route.path == request.path) return &route;
  return nullptr;
}

std::string_view reason_phrase(int status) {
  switch (status) {
    case 200: return "OK";
    case 400: return "Bad Request";
    case 404: return "Not Found";
    case 503: return "Service Unavailable";
    default: return "";  // optional in HTTP/1.1 (RFC 9112, 4)
  }
}

// Closing a socket with unread request bytes (a body this listener does not want) resets the connection, and the
// reset can destroy the answer before the client reads it. So: finish sending, then read what the client still
// sends, for at most a second and kMaxDrainBytes, and only then close.
void close_after_answer(int fd) {
  constexpr std::size_t kMaxDrainBytes = 16 << 20;
  shutdown(fd, SHUT_WR);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(1);
  const timeval wait{0, 100'000};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &wait, sizeof wait);
  std::array<char, 16384> sink;
  for (std::size_t drained = 0; drained < kMaxDrainBytes && std::chrono::steady_clock::now() < deadline;) {
    const ssize_t got = recv(fd, sink.data(), sink.size(), 0);
    if (got == 0 || (got < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) break;
    if (got > 0) drained += std::size_t(got);
  }
  close(fd);
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
  grpc_->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(1));
}

void HealthListener::accept_loop() {
  std::array<pollfd, 2> waiting{pollfd{listen_fd_, POLLIN, 0}, pollfd{wake_fd_, POLLIN, 0}};
  while (!stopping_) {
    if (poll(waiting.data(), waiting.size(), -1) < 0 || waiting[1].revents) continue;  // EINTR, or stop()
    const int connection = accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
    if (connection < 0) continue;
    set_timeouts(connection);
    std::array<char, kHttp2Preface.size()> start{};
    const ssize_t got = recv(connection, start.data(), start.size(), MSG_PEEK | MSG_WAITALL);
    if (got == ssize_t(start.size()) && std::string_view(start.data(), start.size()) == kHttp2Preface) {
      fcntl(connection, F_SETFL, fcntl(connection, F_GETFL) | O_NONBLOCK);
      grpc::AddInsecureChannelFromFd(grpc_.get(), connection);  // gRPC owns the socket from here
      continue;
    }
    answer_http(connection);
    close_after_answer(connection);
  }
}

void HealthListener::answer_http(int connection) {
  std::string head;
  if (!read_head(connection, head)) return;  // the client went away or stalled: nothing to answer
  httplib::Request request;
  httplib::Response response;
  fill_peer(connection, request);
  const bool parsed = parse_head(head, request);
  const HttpRoute* route = parsed ? find_probe(request) : nullptr;
  HttpExchange exchange(service_, request, response, route ? route_name(*route) : kUnmatchedRoute, nullptr, stopping_);
  exchange.record.probe = true;
  if (route)
    route->handle(service_, exchange);
  else if (!parsed)
    exchange.fail({grpc::StatusCode::INVALID_ARGUMENT, "malformed HTTP request"});
  else
    exchange.fail({grpc::StatusCode::NOT_FOUND, "the health listener answers only GET /healthz and GET /readyz"});
  exchange.end();
  std::string answer = "HTTP/1.1 " + std::to_string(response.status) + " " + std::string(reason_phrase(response.status)) + "\r\n";
  for (const auto& [name, value] : response.headers) answer += name + ": " + value + "\r\n";
  answer += "Content-Length: " + std::to_string(response.body.size()) + "\r\nConnection: close\r\n\r\n";
  if (request.method != "HEAD") answer += response.body;
  send_all(connection, answer);
}

}  // namespace k4reg::service
