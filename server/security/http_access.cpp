#include "security/http_access.h"

#include <algorithm>
#include <cctype>
#include <string_view>

#include "security/auth.h"
#include "http/http_exchange.h"

namespace k4reg::service {
namespace {

bool equal_ignoring_case(std::string_view a, std::string_view b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](char x, char y) {
    return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
  });
}

// "https://host:port" -> "host:port"; an opaque origin ("null") stays as it is, and matches no Host.
std::string_view origin_authority(std::string_view origin) {
  const std::size_t scheme_end = origin.find("://");
  return scheme_end == std::string_view::npos ? origin : origin.substr(scheme_end + 3);
}

}  // namespace

grpc::Status check_method(const httplib::Request& request) {
  if (request.method != "CONNECT" && request.method != "TRACE" && request.method != "PRI") return grpc::Status::OK;
  return {grpc::StatusCode::UNIMPLEMENTED,
          request.method + " is not served by the HTTP listener (HTTP/2 and gRPC are on --grpc-listen)"};
}

grpc::Status check_same_origin(const std::string& auth_token, const httplib::Request& request) {
  if (!auth_token.empty() || request.method == "GET" || request.method == "HEAD" ||
      request.method == "OPTIONS" || !request.has_header("Origin"))
    return grpc::Status::OK;
  const std::string origin = request.get_header_value("Origin");
  const std::string host = request.get_header_value("Host");
  if (!host.empty() && equal_ignoring_case(origin_authority(origin), host)) return grpc::Status::OK;
  return {grpc::StatusCode::PERMISSION_DENIED,
          "cross-origin " + request.method + " refused: Origin '" + origin.substr(0, 200) + "' is not this server ('" +
              host.substr(0, 200) + "'); without --auth-token only the server's own page may send it"};
}

grpc::Status check_metrics_access(const ServiceContext& service, const httplib::Request& request) {
  if (service.public_metrics) return grpc::Status::OK;
  const grpc::Status status = check_bearer_token(authorization_header(request), service.auth_token);
  if (status.ok()) return status;
  return {status.error_code(), status.error_message() + " (/metrics and /v1/version are open with --public-metrics)"};
}

void add_page_headers(httplib::Response& response) {
  response.set_header("Content-Security-Policy",
                      "default-src 'none'; script-src 'unsafe-inline'; style-src 'unsafe-inline'; "
                      "img-src data: blob:; connect-src 'self'; base-uri 'none'; form-action 'none'; "
                      "frame-ancestors 'none'");
}

httplib::Headers default_security_headers() {
  return {{"X-Content-Type-Options", "nosniff"}, {"X-Frame-Options", "DENY"}};
}

}  // namespace k4reg::service
