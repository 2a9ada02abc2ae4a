// The HTTP API's request decoding, from untrusted bytes: header fields, then the JSON body of POST
// /v1/register. Bytes up to the first blank line (if there is one) are header fields, parsed by cpp-httplib's
// own reader as the listener parses them, then taken through every step that reads headers before a body
// (the method and same-origin rules, the token, the request id, the declared body size); the rest is the body
// (from_json, protobuf's JSON mapping with unknown fields refused), then what the service does with the
// request (request_checks.h), the same as for a gRPC request.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "security/auth.h"
#include "security/http_access.h"
#include "http/http_body.h"
#include "http/http_exchange.h"
#include "http/http_json.h"
#include "request_checks.h"
#include "observability/request_log.h"

namespace {

using k4reg::fuzz::finding;

void check_refusal(const grpc::Status& status, grpc::StatusCode allowed, const char* step) {
  if (!status.ok() && status.error_code() != allowed) finding(std::string(step) + " refused with another code");
  if (!status.ok() && status.error_message().empty()) finding(std::string(step) + " refused without a reason");
}

void check_head(const httplib::Request& request) {
  check_refusal(k4reg::service::check_method(request), grpc::StatusCode::UNIMPLEMENTED, "check_method");
  check_refusal(k4reg::service::check_same_origin("", request), grpc::StatusCode::PERMISSION_DENIED,
                "check_same_origin");
  check_refusal(k4reg::service::check_bearer_token(k4reg::service::authorization_header(request), "token"),
                grpc::StatusCode::UNAUTHENTICATED, "check_bearer_token");
  const std::string id = k4reg::service::request_id_or_new(request.get_header_value("x-request-id"));
  if (id.empty() || id.size() > 128) finding("a request id out of its bounds");
  const std::atomic<bool> stopping{false};
  k4reg::service::RequestBody body(request, nullptr, stopping, 1 << 20);
  try {
    if (!body.read_all(1 << 20).empty()) finding("a body read from no reader");
  } catch (const k4reg::Error& e) {
    k4reg::fuzz::check_error(e, "request body");
  }
}

// cpp-httplib's request parsing as the listener runs it (Server::process_request over a stream), stopping
// where the listener's pre-routing handler runs: there the head is checked.
class HeadParser : public httplib::Server {
 public:
  HeadParser() {
    set_pre_routing_handler([](const httplib::Request& request, httplib::Response&) {
      check_head(request);
      return HandlerResponse::Handled;
    });
  }
  void parse(std::string_view fields) {
    httplib::detail::BufferStream stream;
    const std::string request_line = "POST /v1/register HTTP/1.1\r\n";
    stream.write(request_line.data(), request_line.size());
    stream.write(fields.data(), fields.size());
    stream.write("\r\n\r\n", 4);
    bool closed = false;
    process_request(stream, true, closed, nullptr);
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string_view input(reinterpret_cast<const char*>(data), size);
  if (const std::size_t blank = input.find("\r\n\r\n"); blank != std::string_view::npos) {
    static HeadParser parser;
    parser.parse(input.substr(0, blank));
    input.remove_prefix(blank + 4);
  }
  k4reg::v1::RegisterRequest request;
  try {
    k4reg::service::from_json(input, request);
  } catch (const k4reg::Error& e) {
    k4reg::fuzz::check_error(e, "invalid JSON");
    return 0;
  }
  k4reg::fuzz::check_register_request(request);
  return 0;
}
