// The one place where the core's error codes become gRPC status codes, and gRPC status codes HTTP statuses
// (the HTTP API answers from the same statuses as gRPC, so the two protocols cannot disagree).
#pragma once

#include <grpcpp/support/status.h>

#include "k4reg/util/error.h"

namespace k4reg::service {

grpc::StatusCode to_grpc_code(ErrorCode code);

// The status for the exception being handled: k4reg::Error by its code, std::bad_alloc as
// RESOURCE_EXHAUSTED, anything else as INTERNAL (a bug). Call only inside a catch block.
grpc::Status status_from_current_exception();

// The HTTP status of a call that ended with `code`. RESOURCE_EXHAUSTED is 413 (a cloud, upload or job over a
// limit: the same request fails again) unless the job queue refused the job for now (`queue_full`): 429.
int to_http_status(grpc::StatusCode code, bool queue_full = false);

}  // namespace k4reg::service
