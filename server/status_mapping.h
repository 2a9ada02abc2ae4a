// The one place where the core's error codes become gRPC status codes (the HTTP API maps from these).
#pragma once

#include <grpcpp/support/status.h>

#include "k4reg/error.h"

namespace k4reg::service {

grpc::StatusCode to_grpc_code(ErrorCode code);

// The status for the exception being handled: k4reg::Error by its code, std::bad_alloc as
// RESOURCE_EXHAUSTED, anything else as INTERNAL (a bug). Call only inside a catch block.
grpc::Status status_from_current_exception();

}  // namespace k4reg::service
