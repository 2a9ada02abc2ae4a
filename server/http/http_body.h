// The body of an HTTP request, read once, as it arrives (cpp-httplib's ContentReader), never held whole
// unless the caller asks for a small one (read_all).
//
// Whatever happens, the body is consumed to its end before the answer goes out, so that the next request on
// a keep-alive connection starts at a request line and the client, still sending, reads the answer instead
// of a connection reset: after a refusal (too large, malformed, unauthorised, ...) the rest is read and
// discarded, for at most kDiscardTime. A body that did not end by then (or broke off) is not complete(): the
// answer then closes the connection. A body declared larger than the listener's payload limit is never read
// (cpp-httplib would skip it whole, with no deadline): its connection closes after the answer.
#pragma once

#include "http/http_lib.h"

#include <atomic>
#include <chrono>
#include <cstdint>
#include <exception>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

namespace k4reg::service {

class RequestBody {
 public:
  // How long a refused body that keeps coming is read and discarded (nginx's lingering_time, with its default):
  // a client that writes its whole body before reading (cpp-httplib's, curl's) must get through it, or it sees a
  // reset instead of the answer. Loopback drains ~1 GB/s, a sanitizer build ~0.1 GB/s; a client that pauses
  // (kDiscardPause) is let go at once.
  static constexpr std::chrono::seconds kDiscardTime{30};
  // What a multipart body may carry besides its parts' contents: delimiters and part headers.
  static constexpr std::uint64_t kMaxFormFramingBytes = 1 << 20;

  // `content` is null for requests without a body reader (GET). Reading stops, and the body is not complete,
  // once `stopping` is set (the server shuts down). `max_body_bytes`: the listener's payload limit.
  RequestBody(const httplib::Request& request, const httplib::ContentReader* content, const std::atomic<bool>& stopping,
              std::uint64_t max_body_bytes);

  // Content-Length, nullopt for a chunked body (size unknown until it ends).
  std::optional<std::uint64_t> declared_bytes() const { return declared_bytes_; }
  bool is_multipart() const { return multipart_; }

  // The whole body. Throws k4reg::Error: kResourceExhausted beyond `max_bytes`, kInvalidArgument if it
  // breaks off.
  std::string read_all(std::uint64_t max_bytes);

  // A multipart/form-data body, part by part: `begin` with each part's headers, then `append` with its
  // bytes in order. Exceptions from either end the reading (the rest is discarded) and are rethrown here;
  // kInvalidArgument if the body is malformed or breaks off.
  void read_multipart(const std::function<void(const httplib::MultipartFormData& part)>& begin,
                      const std::function<void(std::string_view bytes)>& append);

  // Reads and discards what is left (for a refusal before or without reading). Never throws.
  void discard_rest();

  // True once the body has been read to its end: the connection may carry another request.
  bool complete() const { return complete_; }
  // True if reading stopped because the server shuts down.
  bool interrupted() const { return interrupted_; }
  std::uint64_t bytes_received() const { return bytes_received_; }

 private:
  // Runs the reader once with `receive` for the bytes (multipart: `begin` for part headers); after the first
  // exception or once `discarding`, bytes are dropped until the body ends or kDiscardTime passes.
  void read(const std::function<void(std::string_view)>& receive,
            const std::function<void(const httplib::MultipartFormData&)>& begin);
  bool keep_reading();

  const httplib::ContentReader* content_;
  const std::atomic<bool>& stopping_;
  std::optional<std::uint64_t> declared_bytes_;
  std::uint64_t max_body_bytes_;
  bool multipart_ = false, has_body_ = false;
  bool read_ = false, discarding_ = false, complete_ = false, interrupted_ = false;
  std::uint64_t bytes_received_ = 0;
  std::exception_ptr error_;
  std::chrono::steady_clock::time_point discard_until_;
};

}  // namespace k4reg::service
