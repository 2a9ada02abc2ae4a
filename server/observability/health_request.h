// The head (request line and header fields) of one HTTP/1.1 request to the health listener (health_listener.h),
// parsed from untrusted bytes: no step throws or reads outside the input, and the request line, the number of
// header fields and the head's total size are bounded, so every byte sequence ends as a complete head, a need
// for more bytes, or a refusal with its HTTP status. Lines end with CRLF or a bare LF (RFC 9112, 2.2).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace k4reg::service {

// A probe's head is a few hundred bytes; these leave room for the headers a proxy adds and no more.
inline constexpr std::size_t kMaxHealthRequestLineBytes = 1 << 10;
inline constexpr std::size_t kMaxHealthHeaderFields = 32;
inline constexpr std::size_t kMaxHealthHeadBytes = 8 << 10;  // request line, fields and the blank line

struct HealthRequestHead {
  enum class State { kIncomplete, kComplete, kRefused };
  State state = State::kIncomplete;
  std::string method;
  std::string path;  // the request target up to its query
  std::vector<std::pair<std::string, std::string>> fields;  // names as sent, values without surrounding blanks
  // kRefused: 400 (malformed), 414 (request line too long) or 431 (too many fields, or the head too large),
  // and why, for the answer.
  int refusal_status = 0;
  std::string refusal;
};

// `received`: what the connection has sent so far. Complete once the blank line that ends the head is in it;
// anything after that (a body) is left alone.
HealthRequestHead parse_health_request(std::string_view received);

}  // namespace k4reg::service
