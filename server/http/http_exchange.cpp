#include "http/http_exchange.h"

#include "http/http_json.h"
#include "http/http_register.h"
#include "api/status_mapping.h"

namespace k4reg::service {
namespace {

// The peer in gRPC's notation ("ipv4:127.0.0.1:5000"), so access-log lines of both protocols compare.
std::string peer_of(const httplib::Request& request) {
  const bool ipv6 = request.remote_addr.find(':') != std::string::npos;
  return ipv6 ? "ipv6:[" + request.remote_addr + "]:" + std::to_string(request.remote_port)
              : "ipv4:" + request.remote_addr + ":" + std::to_string(request.remote_port);
}

// The answer goes out, then the connection ends: a provider that fails after writing everything makes
// cpp-httplib close the connection instead of reading the unread rest of the body as the next request.
void close_after_answer(httplib::Response& response) {
  std::string content = std::move(response.body);
  response.body.clear();
  const std::string content_type = response.get_header_value("Content-Type");
  response.headers.erase("Content-Type");
  response.set_header("Connection", "close");
  const std::size_t size = content.size();
  response.set_content_provider(size, content_type, [content = std::move(content)](std::size_t, std::size_t, httplib::DataSink& sink) {
    sink.write(content.data(), content.size());
    return false;
  });
}

}  // namespace

HttpExchange::HttpExchange(const ServiceContext& service, const httplib::Request& request, httplib::Response& response,
                           std::string route, const httplib::ContentReader* content, const std::atomic<bool>& stopping)
    : request(request),
      response(response),
      body(request, content, stopping, largest_body_limit(service)),
      service_(service) {
  record.protocol = "http";
  record.method = std::move(route);
  record.peer = peer_of(request);
  record.request_id = request_id_or_new(request.get_header_value("x-request-id"));
  response.set_header("x-request-id", record.request_id);
}

std::optional<std::string_view> authorization_header(const httplib::Request& request) {
  const auto it = request.headers.find("authorization");
  if (it == request.headers.end()) return std::nullopt;
  return std::string_view(it->second);
}

void HttpExchange::reply(const google::protobuf::Message& message) { reply(200, to_json(message), kJsonContentType); }

void HttpExchange::reply(int http_status, std::string content, const char* content_type) {
  response.status = http_status;
  response.set_content(std::move(content), content_type);
}

void HttpExchange::fail(const grpc::Status& status, bool queue_full) {
  fail(status, to_http_status(status.error_code(), queue_full));
  if (queue_full) response.set_header("Retry-After", std::to_string(kRetryAfterQueueFullS));
}

void HttpExchange::fail(const grpc::Status& status, int http_status) {
  record.code = status.error_code();
  record.error = status.error_message();
  reply(http_status, error_json(status, record.request_id), kJsonContentType);
}

void HttpExchange::stream(const char* content_type, std::function<bool(std::string& line)> next,
                          std::function<void(bool)> on_end) {
  streaming_ = true;
  response.status = 200;
  response.set_chunked_content_provider(
      content_type,
      [next = std::move(next)](std::size_t, httplib::DataSink& sink) {
        std::string line;
        if (!next(line)) {
          sink.done();
          return true;
        }
        return sink.write(line.data(), line.size());
      },
      std::move(on_end));
}

void HttpExchange::end() {
  const int status = response.status;
  body.discard_rest();
  response.status = status;  // cpp-httplib sets 400 on the response when the body it reads breaks off
  if (!body.complete()) close_after_answer(response);
  if (body.is_multipart()) record.upload_bytes = body.bytes_received();  // uploaded clouds, as for RegisterStream
  record.http_status = response.status;
  if (!streaming_) service_.end_request(record);
}

void HttpExchange::end_before_body() {
  // cpp-httplib adds Content-Length only to the answers of routes.
  response.set_header("Content-Length", std::to_string(response.body.size()));
  close_after_answer(response);
  record.http_status = response.status;
  service_.end_request(record);
}

}  // namespace k4reg::service
