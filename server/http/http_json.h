// The HTTP API's bodies: the k4reg.v1 messages in protobuf's JSON mapping with the proto field names
// (min_scale_m, not minScaleM), the one conversion between the API's messages and JSON, so the HTTP and the
// gRPC API cannot drift apart. Errors have their own small JSON object.
#pragma once

#include <google/protobuf/message.h>
#include <grpcpp/support/status.h>

#include <string>
#include <string_view>

namespace k4reg::service {

inline constexpr const char* kJsonContentType = "application/json";

// Every field, also those at their default value (0, false, ""), so scripts find each field.
std::string to_json(const google::protobuf::Message& message);

// Unknown fields are refused (a misspelt parameter must not silently take its default). Throws
// k4reg::Error(kInvalidArgument) naming the problem.
void from_json(std::string_view json, google::protobuf::Message& message);

// {"code": "NOT_FOUND", "message": "...", "request_id": "..."}: code is the status code name, as in the
// access log and the gRPC API.
std::string error_json(const grpc::Status& status, const std::string& request_id);

}  // namespace k4reg::service
