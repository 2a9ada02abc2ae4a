// The HTTP/JSON API's routes in one table: HttpServer registers the handlers from it, and the tests check
// the OpenAPI description (server/openapi.json, embedded and served at /openapi.json) against it.
#pragma once

#include <grpcpp/support/status.h>
#include "http/http_lib.h"

#include <span>
#include <string>
#include <string_view>

#include "http/http_exchange.h"
#include "service_context.h"

namespace k4reg::service {

struct HttpRoute {
  std::string_view method;  // "GET", or "POST" for the routes that read a body
  std::string_view path;    // literal, no parameters
  bool probe;               // health, metrics and the API description: access-logged at debug level only
  // Refuses a request from its headers alone, before its body arrives (also the answer to
  // "Expect: 100-continue"); null = nothing to check.
  grpc::Status (*check_headers)(const ServiceContext& service, const httplib::Request& request);
  void (*handle)(const ServiceContext& service, HttpExchange& exchange);
};

std::span<const HttpRoute> http_routes();

// "POST /v1/register": the route's name in the access log and the metrics' method label.
std::string route_name(const HttpRoute& route);

// The OpenAPI 3 description of these routes, embedded from server/openapi.json at build time.
std::string_view openapi_document();

}  // namespace k4reg::service
