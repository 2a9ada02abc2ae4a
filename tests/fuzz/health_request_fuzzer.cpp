// The health listener's request parser (server/observability/health_request.h): arbitrary bytes as what a
// connection sent. Beyond "no crash, no exception": every outcome keeps the parser's promises, and an outcome
// once decided stays so whatever bytes follow (the listener stops reading there).
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_checks.h"
#include "observability/health_request.h"

namespace {

using k4reg::fuzz::finding;
using k4reg::service::HealthRequestHead;
using State = HealthRequestHead::State;

bool has_control(std::string_view text) {
  for (const char c : text)
    if (static_cast<unsigned char>(c) < 0x20 && c != '\t') return true;
  return false;
}

void check_head(const HealthRequestHead& head, std::size_t size) {
  switch (head.state) {
    case State::kIncomplete:
      if (size > k4reg::service::kMaxHealthHeadBytes) finding("an oversized head is still incomplete");
      break;
    case State::kRefused:
      if (head.refusal_status != 400 && head.refusal_status != 414 && head.refusal_status != 431)
        finding("refused with status " + std::to_string(head.refusal_status));
      if (head.refusal.empty()) finding("a refusal without a reason");
      break;
    case State::kComplete:
      if (head.method.empty()) finding("a complete head without a method");
      if (head.method.size() > k4reg::service::kMaxHealthRequestLineBytes) finding("an overlong method accepted");
      if (head.fields.size() > k4reg::service::kMaxHealthHeaderFields) finding("too many fields accepted");
      for (const auto& [name, value] : head.fields)
        if (name.empty() || has_control(name) || has_control(value)) finding("a field with control characters");
      break;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view received(reinterpret_cast<const char*>(data), size);
  const HealthRequestHead head = k4reg::service::parse_health_request(received);
  check_head(head, size);
  if (head.state != State::kIncomplete &&
      k4reg::service::parse_health_request(std::string(received) + "\r\n\r\nmore").state != head.state)
    finding("a decided head changed when more bytes followed");
  return 0;
}
