// Raw loopback TCP clients for the hostile-client tests of the HTTP and health listeners: bytes exactly as
// written (malformed, oversized, slow), and what the server answers.
#pragma once

#include <chrono>
#include <string>
#include <string_view>

namespace k4reg::test {

// A loopback TCP connection to `port`; closed when destroyed. Connecting gives up after a second (a listener
// whose backlog is full drops the SYN, and connect() would retry for minutes).
class Connection {
 public:
  explicit Connection(int port);
  Connection(Connection&& other) noexcept;
  Connection& operator=(Connection&&) = delete;
  ~Connection();

  // False once the server has closed or reset the connection.
  bool send_bytes(std::string_view bytes);
  // What the server sends until it closes (or resets) the connection, waiting at most `timeout` in all.
  std::string read_until_closed(std::chrono::milliseconds timeout);
  bool closed() const { return closed_; }

 private:
  int fd_;
  bool closed_ = false;
};

// The status of an HTTP/1.1 answer, 0 if there is none.
int status_of(const std::string& answer);

// Sends `request` on a new connection and returns the status of the answer, 0 if none comes within 5 s.
int answer_status(int port, std::string_view request);

struct Probe {
  int status = 0;
  std::chrono::steady_clock::duration took{};
};

// GET /healthz as a kubelet sends it, timed from connect to the end of the answer.
Probe probe_healthz(int port);

// GET /healthz on `port` answers 200 within a second.
void expect_quick_probe(int port);

}  // namespace k4reg::test
