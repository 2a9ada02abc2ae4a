// The access log: one line per request with its id, method, status, duration, points and queue wait.
#pragma once

#include <grpcpp/server_context.h>
#include <grpcpp/support/callback_common.h>

#include <chrono>
#include <cstdint>
#include <string>

namespace k4reg::service {

// The request id: the caller's "x-request-id" metadata if it is a sane token (printable ASCII, at most
// 128 characters), otherwise a new random UUID v4.
std::string request_id_of(const grpc::ServerContextBase& context);

// What a call reports when it ends. Filled in by the reactor as the call goes.
struct RequestRecord {
  std::string request_id, method, peer;
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
