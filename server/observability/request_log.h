// The access log of both protocols: one line per request with its id, protocol, method, status, duration,
// points and queue wait. gRPC and HTTP share the request id scheme ("x-request-id") and this format.
#pragma once

#include <grpcpp/server_context.h>
#include <grpcpp/support/callback_common.h>

#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>

namespace k4reg::service {

// The request id: the caller's "x-request-id" (gRPC metadata or HTTP header; "" when absent) if it is a
// sane token (printable ASCII without quotes or backslashes, at most 128 characters), otherwise a new random
// UUID v4.
std::string request_id_or_new(std::string_view offered);

// What a call reports when it ends. Filled in by the reactor or HTTP handler as the call goes.
struct RequestRecord {
  std::string request_id, method, peer;
  std::string protocol = "grpc";  // or "http"
  int http_status = 0;            // HTTP only
  bool probe = false;             // health, metrics and API description requests: logged at debug level
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  grpc::StatusCode code = grpc::StatusCode::OK;
  std::string error;  // status message when not OK
  std::uint64_t source_points = 0, target_points = 0, upload_bytes = 0;
  double queue_wait_s = 0, registration_s = 0;
};

// The record of a call that starts now: method, request id (echoed to the caller as initial metadata), peer.
RequestRecord open_request(grpc::CallbackServerContext& context, const char* method);

void log_request(const RequestRecord& record);

}  // namespace k4reg::service
