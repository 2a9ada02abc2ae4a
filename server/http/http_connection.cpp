#include "http/http_connection.h"

#include <fmt/format.h>
#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <exception>
#include <limits>

#include "observability/json_log.h"

namespace k4reg::service {
namespace {

using Clock = BoundedSocketStream::Clock;

thread_local BoundedSocketStream* current_stream = nullptr;

// How long to wait for one chunk of a request: short enough for stop() to be noticed between polls.
constexpr std::chrono::milliseconds kPollSlice{100};

bool poll_for(socket_t fd, short events, int timeout_ms) {
  pollfd ready{fd, events, 0};
  int result;
  while ((result = poll(&ready, 1, timeout_ms)) < 0 && errno == EINTR) {
  }
  return result > 0;
}

void address_of(socket_t fd, bool peer, std::string& ip, int& port) {
  sockaddr_storage address{};
  socklen_t size = sizeof address;
  if ((peer ? getpeername(fd, reinterpret_cast<sockaddr*>(&address), &size)
            : getsockname(fd, reinterpret_cast<sockaddr*>(&address), &size)) != 0)
    return;
  char host[NI_MAXHOST] = {};
  char service[NI_MAXSERV] = {};
  if (getnameinfo(reinterpret_cast<sockaddr*>(&address), size, host, sizeof host, service, sizeof service,
                  NI_NUMERICHOST | NI_NUMERICSERV) != 0)
    return;
  ip = host;
  port = std::atoi(service);
}

const char* reason_phrase(int status) {
  switch (status) {
    case 408:
      return "Request Timeout";
    case 414:
      return "URI Too Long";
    case 431:
      return "Request Header Fields Too Large";
    default:
      return "Bad Request";
  }
}

}  // namespace

BoundedSocketStream::BoundedSocketStream(socket_t fd, std::chrono::seconds read_timeout,
                                         std::chrono::seconds write_timeout)
    : fd_(fd), read_timeout_(read_timeout), write_timeout_(write_timeout) {}

BoundedSocketStream* BoundedSocketStream::current() { return current_stream; }

bool BoundedSocketStream::wait_for_request(std::chrono::seconds idle, const std::atomic<socket_t>& listener) {
  const auto end = Clock::now() + idle;
  while (listener != INVALID_SOCKET) {
    if (buffer_start_ < buffer_.size()) return true;
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(end - Clock::now());
    if (left.count() <= 0) return false;
    if (poll_for(fd_, POLLIN, int(std::min(left, kPollSlice).count()))) return true;
  }
  return false;
}

void BoundedSocketStream::start_request() {
  in_head_ = true;
  head_bytes_ = head_lines_ = 0;
  head_deadline_ = Clock::now() + kHeadDeadline;
  body_bytes_ = handed_on_ = 0;
  unhanded_limit_ = std::numeric_limits<std::uint64_t>::max() / 2;
  head_refusal_.clear();
  head_refusal_status_ = 0;
  wrote_ = discarding_ = false;
}

ssize_t BoundedSocketStream::refuse_head(int status, std::string reason) {
  if (head_refusal_.empty()) {
    head_refusal_status_ = status;
    head_refusal_ = std::move(reason);
  }
  return -1;
}

int BoundedSocketStream::read_wait_ms() const {
  auto wait = discarding_ ? std::min<std::chrono::milliseconds>(read_timeout_, kDiscardPause) : read_timeout_;
  if (in_head_)
    wait = std::min(wait, std::chrono::ceil<std::chrono::milliseconds>(head_deadline_ - Clock::now()));
  return int(std::max<std::chrono::milliseconds::rep>(wait.count(), 0));
}

bool BoundedSocketStream::is_readable() const {
  return buffer_start_ < buffer_.size() || poll_for(fd_, POLLIN, read_wait_ms());
}

bool BoundedSocketStream::is_writable() const { return poll_for(fd_, POLLOUT, int(write_timeout_.count())); }

ssize_t BoundedSocketStream::read(char* ptr, size_t size) {
  if (!head_refusal_.empty() || over_unhanded_limit()) return -1;
  if (in_head_) {
    if (head_bytes_ >= kMaxHeadBytes)
      return refuse_head(head_lines_ == 0 ? 414 : 431,
                         fmt::format("request head over {} bytes (the HTTP listener's limit)", kMaxHeadBytes));
    size = std::min(size, kMaxHeadBytes - head_bytes_);
  }
  if (buffer_start_ == buffer_.size()) {
    if (!is_readable()) {
      if (in_head_ && Clock::now() >= head_deadline_)
        return refuse_head(408, fmt::format("request head not complete within {} s (the HTTP listener's limit)",
                                            kHeadDeadline.count()));
      return -1;
    }
    buffer_.resize(CPPHTTPLIB_RECV_BUFSIZ);
    ssize_t got;
    while ((got = recv(fd_, buffer_.data(), buffer_.size(), 0)) < 0 && errno == EINTR) {
    }
    buffer_.resize(std::size_t(std::max<ssize_t>(got, 0)));
    buffer_start_ = 0;
    if (got <= 0) return got;
  }
  const std::size_t count = std::min(size, buffer_.size() - buffer_start_);
  std::copy_n(buffer_.data() + buffer_start_, count, ptr);
  buffer_start_ += count;
  if (!in_head_) {
    body_bytes_ += count;
    return ssize_t(count);
  }
  head_bytes_ += count;
  head_lines_ += std::size_t(std::count(ptr, ptr + count, '\n'));
  // The request line and the blank line that ends the head are lines too.
  if (head_lines_ > kMaxHeaderFields + 2)
    return refuse_head(431, fmt::format("more than {} header fields (the HTTP listener's limit)", kMaxHeaderFields));
  return ssize_t(count);
}

ssize_t BoundedSocketStream::write(const char* ptr, size_t size) {
  if (!is_writable()) return -1;
  ssize_t sent;
  while ((sent = send(fd_, ptr, size, MSG_NOSIGNAL)) < 0 && errno == EINTR) {
  }
  if (sent > 0) wrote_ = true;
  return sent;
}

void BoundedSocketStream::get_remote_ip_and_port(std::string& ip, int& port) const { address_of(fd_, true, ip, port); }

void BoundedSocketStream::get_local_ip_and_port(std::string& ip, int& port) const { address_of(fd_, false, ip, port); }

void BoundedHttpServer::widen_backlog() { ::listen(svr_sock_, SOMAXCONN); }

bool BoundedHttpServer::process_and_close_socket(socket_t sock) {
  BoundedSocketStream stream(sock, std::chrono::seconds(read_timeout_sec_), std::chrono::seconds(write_timeout_sec_));
  current_stream = &stream;
  bool ok = false;
  try {
    for (std::size_t served = 0; served < keep_alive_max_count_; ++served) {
      if (!stream.wait_for_request(std::chrono::seconds(keep_alive_timeout_sec_), svr_sock_)) break;
      stream.start_request();
      bool closed = false;
      ok = process_request(stream, served + 1 == keep_alive_max_count_, closed, nullptr);
      if (!stream.head_refusal().empty() && !stream.wrote_anything()) answer_head_refusal(stream);
      if (!ok || closed || !stream.head_refusal().empty()) break;
    }
  } catch (...) {
    // A bug, not the client's doing: this connection ends, the listener and its other connections go on.
    try {
      std::rethrow_exception(std::current_exception());
    } catch (const std::exception& e) {
      log_json(spdlog::level::err, "http connection failed", {{"error", e.what()}});
    } catch (...) {
      log_json(spdlog::level::err, "http connection failed", {{"error", "unknown exception"}});
    }
    ok = false;
  }
  current_stream = nullptr;
  shutdown(sock, SHUT_RDWR);
  close(sock);
  return ok;
}

// cpp-httplib answers nothing when the request line itself is cut: the answer is written here, with the
// same JSON error as every other refusal.
void BoundedHttpServer::answer_head_refusal(BoundedSocketStream& stream) {
  httplib::Request request;
  httplib::Response response;
  stream.get_remote_ip_and_port(request.remote_addr, request.remote_port);
  response.status = stream.head_refusal_status();
  if (head_refusal_) head_refusal_(request, response);
  std::string answer = fmt::format("HTTP/1.1 {} {}\r\n", response.status, reason_phrase(response.status));
  for (const auto& [name, value] : response.headers) answer += name + ": " + value + "\r\n";
  answer += fmt::format("Content-Length: {}\r\nConnection: close\r\n\r\n", response.body.size()) + response.body;
  for (std::size_t sent = 0; sent < answer.size();) {
    const ssize_t done = stream.write(answer.data() + sent, answer.size() - sent);
    if (done <= 0) return;
    sent += std::size_t(done);
  }
}

}  // namespace k4reg::service
