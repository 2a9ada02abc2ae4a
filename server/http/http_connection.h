// The plaintext HTTP listener's connections, served by cpp-httplib's request parser over a socket stream of our
// own that bounds what a client may cost before its request is even routed.
//
// cpp-httplib 0.11.4 (Debian 12, compiled into its shared library, so its CPPHTTPLIB_* limits cannot be changed)
// reads the request line and header fields with no bound on their size or number and no deadline but a
// per-recv read timeout: a header flood grows memory without end and a client sending a byte every few
// seconds holds a connection thread for ever. Its parser stays in charge; the stream under it refuses to
// deliver more than kMaxHeadBytes or kMaxHeaderFields of a request's head, or to wait for them past kHeadDeadline,
// and the answer then names the limit (431 or 408).
#pragma once

#include "http/http_lib.h"

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>

namespace k4reg::service {

// The head of a request (request line, header fields, blank line): a browser's is under 2 KiB.
inline constexpr std::size_t kMaxHeadBytes = 32 << 10;
inline constexpr std::size_t kMaxHeaderFields = 100;
// From the request's first byte to its blank line.
inline constexpr std::chrono::seconds kHeadDeadline{10};
inline constexpr std::chrono::seconds kDiscardPause{1};

// One connection's socket as cpp-httplib's Stream, with the head's budget.
class BoundedSocketStream final : public httplib::Stream {
 public:
  using Clock = std::chrono::steady_clock;

  BoundedSocketStream(socket_t fd, std::chrono::seconds read_timeout, std::chrono::seconds write_timeout);

  // Waits up to `idle` for the next request's first byte; false if none comes (or `running` turns false).
  bool wait_for_request(std::chrono::seconds idle, const std::atomic<socket_t>& listener);
  // A request starts: its head gets the budget until head_complete().
  void start_request();
  // The head was parsed (the request is being routed): its body reads under the read timeout only.
  void head_complete() { in_head_ = false; }

  // Why the head's budget stopped reading ("" while within it), and the status that says so.
  const std::string& head_refusal() const { return head_refusal_; }
  int head_refusal_status() const { return head_refusal_status_; }
  // A multipart body: cpp-httplib's parser keeps what is not part content (delimiters, part headers, and
  // anything after the closing delimiter) in memory; reading stops once more than `limit` bytes of the body
  // were not handed on as part contents (`handed_on` counts those).
  void limit_unhanded(std::uint64_t limit) { unhanded_limit_ = limit; }
  void handed_on(std::uint64_t bytes) { handed_on_ += bytes; }
  bool over_unhanded_limit() const { return body_bytes_ > handed_on_ + unhanded_limit_; }
  // The rest of a refused body is being read and dropped: a client that stops sending for kDiscardPause is not
  // waiting on its upload and will read the answer, so reading ends then.
  void discarding() { discarding_ = true; }
  bool wrote_anything() const { return wrote_; }

  // The connection whose request this thread is handling, or null.
  static BoundedSocketStream* current();

  bool is_readable() const override;
  bool is_writable() const override;
  ssize_t read(char* ptr, size_t size) override;
  ssize_t write(const char* ptr, size_t size) override;
  void get_remote_ip_and_port(std::string& ip, int& port) const override;
  void get_local_ip_and_port(std::string& ip, int& port) const override;
  socket_t socket() const override { return fd_; }

 private:
  // Notes the first refusal; returns -1, the read's failure.
  ssize_t refuse_head(int status, std::string reason);
  // Milliseconds to wait for input: the read timeout, or less where the head's deadline comes first.
  int read_wait_ms() const;

  socket_t fd_;
  std::chrono::milliseconds read_timeout_, write_timeout_;
  bool in_head_ = false, wrote_ = false, discarding_ = false;
  std::size_t head_bytes_ = 0, head_lines_ = 0;
  Clock::time_point head_deadline_;
  std::uint64_t body_bytes_ = 0, handed_on_ = 0, unhanded_limit_ = 0;
  std::string head_refusal_;
  int head_refusal_status_ = 0;
  // Bytes received but not yet delivered: the head is read a byte at a time.
  std::string buffer_;
  std::size_t buffer_start_ = 0;
};

// cpp-httplib's plaintext server with its connection loop on BoundedSocketStream: keep-alive, the head's
// budget, and a catch at the connection's boundary (whatever escapes a request closes its connection only).
class BoundedHttpServer : public httplib::Server {
 public:
  // Called with the refusal when a head over its budget got no answer from cpp-httplib (it gives none when
  // the request line itself is cut): fills the answer that goes out before the connection closes.
  using HeadRefusal = std::function<void(const httplib::Request& request, httplib::Response& response)>;
  void set_head_refusal_handler(HeadRefusal handler) { head_refusal_ = std::move(handler); }
  // After binding: cpp-httplib listens with a backlog of 5 (compiled in), and a burst of connections beyond it
  // has its SYNs dropped and retried a second later; the kernel's maximum instead.
  void widen_backlog();

 private:
  bool process_and_close_socket(socket_t sock) override;
  void answer_head_refusal(BoundedSocketStream& stream);

  HeadRefusal head_refusal_;
};

}  // namespace k4reg::service
