#include "raw_connection.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <utility>

namespace k4reg::test {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

Connection::Connection(int port) : fd_(socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0)) {
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(std::uint16_t(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const int started = connect(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address);
  pollfd writable{fd_, POLLOUT, 0};
  int error = 0;
  socklen_t size = sizeof error;
  if (fd_ < 0 || (started != 0 && (errno != EINPROGRESS || poll(&writable, 1, 1000) != 1)) ||
      getsockopt(fd_, SOL_SOCKET, SO_ERROR, &error, &size) != 0 || error != 0) {
    if (fd_ >= 0) close(fd_);
    throw std::runtime_error("cannot connect to port " + std::to_string(port) + " within a second");
  }
  fcntl(fd_, F_SETFL, fcntl(fd_, F_GETFL) & ~O_NONBLOCK);
}

Connection::Connection(Connection&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}

Connection::~Connection() {
  if (fd_ >= 0) close(fd_);
}

bool Connection::send_bytes(std::string_view bytes) {
  for (std::size_t sent = 0; sent < bytes.size();) {
    const ssize_t done = send(fd_, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (done <= 0) return false;
    sent += std::size_t(done);
  }
  return true;
}

std::string Connection::read_until_closed(std::chrono::milliseconds timeout) {
  std::string received;
  const auto deadline = Clock::now() + timeout;
  for (char buffer[4096];;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    pollfd readable{fd_, POLLIN, 0};
    if (left <= 0 || poll(&readable, 1, int(left)) <= 0) return received;
    const ssize_t got = recv(fd_, buffer, sizeof buffer, 0);
    if (got <= 0) {
      closed_ = true;
      return received;
    }
    received.append(buffer, std::size_t(got));
  }
}

int status_of(const std::string& answer) {
  return answer.starts_with("HTTP/1.1 ") && answer.size() >= 12 ? std::atoi(answer.substr(9, 3).c_str()) : 0;
}

int answer_status(int port, std::string_view request) {
  Connection connection(port);
  connection.send_bytes(request);  // the server may answer and close before taking all of a flood
  return status_of(connection.read_until_closed(5s));
}

Probe probe_healthz(int port) {
  const auto start = Clock::now();
  Connection connection(port);
  connection.send_bytes(
      "GET /healthz HTTP/1.1\r\nHost: 127.0.0.1\r\nUser-Agent: kube-probe/1.29\r\nConnection: close\r\n\r\n");
  const int status = status_of(connection.read_until_closed(3s));
  return {status, Clock::now() - start};
}

void expect_quick_probe(int port) {
  const Probe probe = probe_healthz(port);
  EXPECT_EQ(probe.status, 200);
  EXPECT_LT(probe.took, 1s) << std::chrono::duration_cast<std::chrono::milliseconds>(probe.took).count() << " ms";
}

}  // namespace k4reg::test
