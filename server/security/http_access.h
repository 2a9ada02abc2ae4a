// Who may do what over HTTP, decided from a request's head before any of its body is read: the methods the
// listener serves, the same-origin rule for state-changing requests when no token is set (a page elsewhere, or
// a DNS-rebound name, must not drive a local server through the visitor's browser), the token on /metrics and
// /v1/version, and the headers that keep the QA page out of frames and its content types as sent.
#pragma once

#include <grpcpp/support/status.h>
#include "http/http_lib.h"

#include "service_context.h"

namespace k4reg::service {

// UNIMPLEMENTED (405) for CONNECT, TRACE and PRI: cpp-httplib would read a PRI body whole into memory.
grpc::Status check_method(const httplib::Request& request);

// Without a token (`auth_token` empty), PERMISSION_DENIED (403) for a POST, PUT, PATCH or DELETE whose Origin
// header is not this server as the client addressed it (the Host header). Requests without Origin (curl,
// clients) pass.
grpc::Status check_same_origin(const std::string& auth_token, const httplib::Request& request);

// /metrics and /v1/version: UNAUTHENTICATED without the token where one is set, unless --public-metrics.
grpc::Status check_metrics_access(const ServiceContext& service, const httplib::Request& request);

// The page's Content-Security-Policy: its own inline scripts and styles, nothing loaded from elsewhere.
void add_page_headers(httplib::Response& response);
// On every answer: no MIME sniffing, no framing (X-Frame-Options: DENY).
httplib::Headers default_security_headers();

}  // namespace k4reg::service
