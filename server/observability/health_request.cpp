#include "observability/health_request.h"

#include <algorithm>

namespace k4reg::service {
namespace {

using State = HealthRequestHead::State;

// RFC 9110, 5.6.2: the characters of a method or a field name.
bool is_token_char(char c) {
  return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
         std::string_view("!#$%&'*+-.^_`|~").find(c) != std::string_view::npos;
}

bool is_token(std::string_view text) { return !text.empty() && std::all_of(text.begin(), text.end(), is_token_char); }

// An origin-form target or any other: visible ASCII.
bool is_target(std::string_view text) {
  return !text.empty() && std::all_of(text.begin(), text.end(), [](char c) { return c > 0x20 && c < 0x7F; });
}

// RFC 9110, 5.5: visible characters, obs-text (0x80-0xFF), spaces and tabs; no other control character.
bool is_field_value(std::string_view text) {
  return std::all_of(text.begin(), text.end(), [](char c) {
    const auto byte = static_cast<unsigned char>(c);
    return byte == '\t' || (byte >= 0x20 && byte != 0x7F);
  });
}

bool is_digit(char c) { return c >= '0' && c <= '9'; }

// "HTTP/1.1", "HTTP/1.0".
bool is_version(std::string_view text) {
  return text.size() == 8 && text.starts_with("HTTP/") && is_digit(text[5]) && text[6] == '.' && is_digit(text[7]);
}

std::string_view without_blanks(std::string_view text) {
  const std::size_t first = text.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  return text.substr(first, text.find_last_not_of(" \t") - first + 1);
}

// "GET /readyz?x HTTP/1.1": method, target and version separated by single spaces.
bool parse_request_line(std::string_view line, HealthRequestHead& head) {
  const std::size_t method_end = line.find(' ');
  if (method_end == std::string_view::npos) return false;
  const std::string_view method = line.substr(0, method_end), rest = line.substr(method_end + 1);
  const std::size_t target_end = rest.find(' ');
  if (target_end == std::string_view::npos) return false;
  const std::string_view target = rest.substr(0, target_end), version = rest.substr(target_end + 1);
  if (!is_token(method) || !is_target(target) || !is_version(version)) return false;
  head.method = method;
  head.path = target.substr(0, target.find('?'));
  return true;
}

// "Name: value", the name right before the colon (RFC 9112, 5.1); the value may be empty.
bool parse_field(std::string_view line, HealthRequestHead& head) {
  const std::size_t colon = line.find(':');
  if (colon == std::string_view::npos) return false;
  const std::string_view name = line.substr(0, colon), value = without_blanks(line.substr(colon + 1));
  if (!is_token(name) || !is_field_value(value)) return false;
  head.fields.emplace_back(name, value);
  return true;
}

HealthRequestHead refused(int status, std::string why) {
  HealthRequestHead head;
  head.state = State::kRefused;
  head.refusal_status = status;
  head.refusal = std::move(why);
  return head;
}

const std::string kLineTooLong = "the request line is over " + std::to_string(kMaxHealthRequestLineBytes) + " bytes";
const std::string kHeadTooLarge = "the request head is over " + std::to_string(kMaxHealthHeadBytes) + " bytes";

}  // namespace

HealthRequestHead parse_health_request(std::string_view received) {
  HealthRequestHead head;
  bool at_request_line = true;
  for (std::size_t start = 0;;) {
    const std::size_t end = received.find('\n', start);
    if (end == std::string_view::npos) break;
    if (end >= kMaxHealthHeadBytes) return refused(431, kHeadTooLarge);
    std::string_view line = received.substr(start, end - start);
    if (line.ends_with('\r')) line.remove_suffix(1);
    start = end + 1;
    if (at_request_line) {
      if (line.size() > kMaxHealthRequestLineBytes) return refused(414, kLineTooLong);
      if (!parse_request_line(line, head)) return refused(400, "malformed request line");
      at_request_line = false;
    } else if (line.empty()) {
      head.state = State::kComplete;
      return head;
    } else if (head.fields.size() == kMaxHealthHeaderFields) {
      return refused(431, "more than " + std::to_string(kMaxHealthHeaderFields) + " header fields");
    } else if (!parse_field(line, head)) {
      return refused(400, "malformed header field");
    }
  }
  // The head has not ended yet: more bytes may come, unless it is already too long.
  if (received.size() > kMaxHealthHeadBytes) return at_request_line ? refused(414, kLineTooLong) : refused(431, kHeadTooLarge);
  return head;
}

}  // namespace k4reg::service
