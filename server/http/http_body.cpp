#include "http/http_body.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>

#include "http/http_connection.h"
#include "k4reg/util/error.h"

namespace k4reg::service {
namespace {

bool contains_case_insensitive(std::string_view text, std::string_view word) {
  return std::search(text.begin(), text.end(), word.begin(), word.end(), [](char a, char b) {
           return std::tolower(static_cast<unsigned char>(a)) == std::tolower(static_cast<unsigned char>(b));
         }) != text.end();
}

}  // namespace

RequestBody::RequestBody(const httplib::Request& request, const httplib::ContentReader* content,
                         const std::atomic<bool>& stopping, std::uint64_t max_body_bytes)
    : content_(content), stopping_(stopping), max_body_bytes_(max_body_bytes) {
  const bool chunked = contains_case_insensitive(request.get_header_value("Transfer-Encoding"), "chunked");
  if (!chunked && request.has_header("Content-Length"))
    declared_bytes_ = request.get_header_value<std::uint64_t>("Content-Length");
  // Without Content-Length or chunked encoding an HTTP/1.1 request has no body (cpp-httplib would wait for
  // the connection to close).
  has_body_ = content_ && (chunked || declared_bytes_.value_or(0) > 0);
  multipart_ = request.is_multipart_form_data();
  complete_ = !has_body_;
}

bool RequestBody::keep_reading() {
  if (stopping_) {
    interrupted_ = true;
    return false;
  }
  return !(error_ || discarding_) || std::chrono::steady_clock::now() < discard_until_;
}

void RequestBody::read(const std::function<void(std::string_view)>& receive,
                       const std::function<void(const httplib::MultipartFormData&)>& begin) {
  if (read_) fail(ErrorCode::kInternal, "the request body was read twice");
  read_ = true;
  if (!has_body_) return;
  if (declared_bytes_ > max_body_bytes_)
    fail(ErrorCode::kResourceExhausted,
         fmt::format("request body of {} bytes, over the HTTP listener's limit of {} bytes (from --max-upload-mb and "
                     "--max-inline-mb)",
                     *declared_bytes_, max_body_bytes_));
  BoundedSocketStream* connection = BoundedSocketStream::current();
  const auto refuse = [this, connection] {
    error_ = std::current_exception();
    discard_until_ = std::chrono::steady_clock::now() + kDiscardTime;
    if (connection) connection->discarding();
  };
  if (discarding_ && connection) connection->discarding();
  // Plaintext connections bound what the multipart parser holds back (BoundedSocketStream); TLS ones cannot.
  BoundedSocketStream* stream = multipart_ ? connection : nullptr;
  if (stream) stream->limit_unhanded(kMaxFormFramingBytes);
  const auto on_bytes = [&](const char* data, std::size_t size) {
    bytes_received_ += size;
    if (stream) stream->handed_on(size);
    if (!keep_reading()) return false;
    if (error_ || discarding_) return true;
    try {
      receive(std::string_view(data, size));
    } catch (...) {
      refuse();
    }
    return true;
  };
  // cpp-httplib parses every multipart/form-data body into parts, even for the plain reader.
  const bool ended = multipart_ ? (*content_)(
                                      [&](const httplib::MultipartFormData& part) {
                                        if (!keep_reading()) return false;
                                        if (error_ || discarding_) return true;
                                        try {
                                          begin(part);
                                        } catch (...) {
                                          refuse();
                                        }
                                        return true;
                                      },
                                      on_bytes)
                                : (*content_)(on_bytes);
  complete_ = ended;
  if (error_) std::rethrow_exception(error_);
  if (stream && stream->over_unhanded_limit())
    fail(ErrorCode::kResourceExhausted,
         fmt::format("multipart/form-data body with more than {} bytes besides its parts' contents (delimiters, part "
                     "headers, anything after the closing delimiter)",
                     kMaxFormFramingBytes));
  if (interrupted_) fail(ErrorCode::kCancelled, "the server is shutting down");
  if (!ended)
    fail(ErrorCode::kInvalidArgument, multipart_ ? "malformed or incomplete multipart/form-data body"
                                                 : "incomplete request body");
}

std::string RequestBody::read_all(std::uint64_t max_bytes) {
  if (declared_bytes_ && *declared_bytes_ > max_bytes) {
    discard_rest();
    fail(ErrorCode::kResourceExhausted,
         fmt::format("request body of {} bytes, at most {} allowed", *declared_bytes_, max_bytes));
  }
  std::string bytes;
  read(
      [&](std::string_view data) {
        if (bytes.size() + data.size() > max_bytes)
          fail(ErrorCode::kResourceExhausted, fmt::format("request body over {} bytes", max_bytes));
        bytes.append(data);
      },
      [](const httplib::MultipartFormData&) {});
  return bytes;
}

void RequestBody::read_multipart(const std::function<void(const httplib::MultipartFormData& part)>& begin,
                                 const std::function<void(std::string_view bytes)>& append) {
  if (!multipart_) fail(ErrorCode::kInvalidArgument, "expected a multipart/form-data body");
  read(append, begin);
}

void RequestBody::discard_rest() {
  if (read_) return;
  discarding_ = true;
  discard_until_ = std::chrono::steady_clock::now() + kDiscardTime;
  try {
    read([](std::string_view) {}, [](const httplib::MultipartFormData&) {});
  } catch (const std::exception&) {
    // Whatever broke, the answer is already decided; complete() tells whether the connection survives.
  }
}

}  // namespace k4reg::service
