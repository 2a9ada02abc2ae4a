// gRPC status codes by the names scripts, logs and people use (OK, RESOURCE_EXHAUSTED, ...): one table
// for the server's access log and the client's messages.
#pragma once

#include <grpcpp/support/status.h>

namespace k4reg {

const char* status_code_name(grpc::StatusCode code);

}  // namespace k4reg
