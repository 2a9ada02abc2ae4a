// The gRPC request decoder: arbitrary bytes parsed as a Register request and as a RegisterStream message (the
// stream's UploadHeader carries the same parameters), then what the service does with them (request_checks.h).
#include <cstddef>
#include <cstdint>

#include "request_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > static_cast<std::size_t>(INT32_MAX)) return 0;
  const int length = static_cast<int>(size);
  k4reg::v1::RegisterRequest request;
  if (request.ParseFromArray(data, length)) k4reg::fuzz::check_register_request(request);
  k4reg::v1::RegisterStreamRequest message;
  if (message.ParseFromArray(data, length) && message.has_header())
    k4reg::fuzz::check_params(message.header().params());
  return 0;
}
