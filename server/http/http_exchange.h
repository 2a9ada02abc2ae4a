// One HTTP request being answered: the HTTP counterpart of a gRPC reactor's call. It carries the access-log
// record (request id from the "x-request-id" header or a new one, echoed as a response header), the body
// reader and the JSON answers, and ends like a gRPC call: the body consumed, one access-log line, metrics.
#pragma once

#include <google/protobuf/message.h>
#include <grpcpp/support/status.h>
#include "http/http_lib.h"

#include <atomic>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "http/http_body.h"
#include "observability/request_log.h"
#include "service_context.h"

namespace k4reg::service {

class HttpExchange {
 public:
  // `route` names the request in logs and metrics ("POST /v1/register"); `content` is null without a body.
  HttpExchange(const ServiceContext& service, const httplib::Request& request, httplib::Response& response,
               std::string route, const httplib::ContentReader* content, const std::atomic<bool>& stopping);
  HttpExchange(const HttpExchange&) = delete;
  HttpExchange& operator=(const HttpExchange&) = delete;

  // 200 with `message` as JSON.
  void reply(const google::protobuf::Message& message);
  void reply(int http_status, std::string content, const char* content_type);
  // The error answer {code, message, request_id}: HTTP status from status_mapping (429 with Retry-After).
  void fail(const grpc::Status& status, bool queue_full = false);
  void fail(const grpc::Status& status, int http_status);
  // 200 with a chunked body: the lines `next` gives (on this connection's thread, after the handler returns)
  // until it returns false. `on_end` runs when the answer ends (true: delivered; false: the client went away)
  // and writes the access-log line itself: end() then leaves it out.
  void stream(const char* content_type, std::function<bool(std::string& line)> next, std::function<void(bool)> on_end);

  // Consumes what is left of the body (closing the connection after the answer if it does not end), then
  // writes the access-log line and the metrics. Call once the answer is set.
  void end();
  // end() for a final answer to "Expect: 100-continue": the client may send the body all the same (RFC 9110,
  // 10.1.1), which must not be read as the next request, so the connection closes after the answer.
  void end_before_body();

  const httplib::Request& request;
  httplib::Response& response;
  RequestBody body;
  RequestRecord record;

 private:
  const ServiceContext& service_;
  bool streaming_ = false;
};

// The "authorization" header, nullopt without one.
std::optional<std::string_view> authorization_header(const httplib::Request& request);

// After a 429 the client should wait this long: a slot frees as soon as any queued job starts.
inline constexpr int kRetryAfterQueueFullS = 1;

}  // namespace k4reg::service
