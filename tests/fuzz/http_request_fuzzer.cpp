// The HTTP API's request decoder: arbitrary bytes as the JSON body of POST /v1/register (from_json, protobuf's
// JSON mapping with unknown fields refused), then what the service does with the request (request_checks.h),
// the same as for a gRPC request.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "http_json.h"
#include "request_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  k4reg::v1::RegisterRequest request;
  try {
    k4reg::service::from_json(std::string_view(reinterpret_cast<const char*>(data), size), request);
  } catch (const k4reg::Error& e) {
    k4reg::fuzz::check_error(e, "invalid JSON");
    return 0;
  }
  k4reg::fuzz::check_register_request(request);
  return 0;
}
