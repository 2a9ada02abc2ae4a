#include "http/http_routes.h"

#include "grpc/health/v1/health.pb.h"
#include "security/http_access.h"
#include "http/http_json.h"
#include "http/http_register.h"
#include "http/http_register_project.h"
#include "observability/metrics.h"
#include "web_page.h"

namespace k4reg::service {
namespace {

// The same message as the gRPC health service answers: {"status": "SERVING"}.
grpc::health::v1::HealthCheckResponse serving() {
  grpc::health::v1::HealthCheckResponse health;
  health.set_status(grpc::health::v1::HealthCheckResponse::SERVING);
  return health;
}

// Liveness: answering at all is the test.
void handle_healthz(const ServiceContext&, HttpExchange& exchange) { exchange.reply(serving()); }

// Readiness, as the gRPC "readiness" health service: 503 while draining or while the job queue is full.
void handle_readyz(const ServiceContext& service, HttpExchange& exchange) {
  if (const grpc::Status status = service.readiness(); !status.ok()) {
    exchange.fail(status);
    return;
  }
  exchange.reply(serving());
}

// Answers the refusal where check_metrics_access refuses; true then.
bool refused_without_metrics_access(const ServiceContext& service, HttpExchange& exchange) {
  const grpc::Status status = check_metrics_access(service, exchange.request);
  if (!status.ok()) exchange.fail(status);
  return !status.ok();
}

void handle_version(const ServiceContext& service, HttpExchange& exchange) {
  if (refused_without_metrics_access(service, exchange)) return;
  exchange.reply(service.server_info);
}

// The QA page (web/): upload scans, watch the job, look at the result. Open like the API description: it is
// the same for everyone and holds no data; registering through it needs the token where one is set.
void handle_page(const ServiceContext&, HttpExchange& exchange) {
  exchange.reply(200, web::render_page(nullptr), "text/html; charset=utf-8");
  add_page_headers(exchange.response);
}

void handle_openapi(const ServiceContext&, HttpExchange& exchange) {
  exchange.reply(200, std::string(openapi_document()), kJsonContentType);
}

void handle_metrics(const ServiceContext& service, HttpExchange& exchange) {
  if (refused_without_metrics_access(service, exchange)) return;
  Metrics::Snapshot snapshot;
  snapshot.queue_depth = service.queue.waiting();
  snapshot.queue_capacity = service.queue.capacity();
  snapshot.workers_busy = service.queue.running();
  snapshot.workers = service.queue.workers();
  snapshot.pair_queue_depth = service.pair_queue.waiting();
  snapshot.pair_workers_busy = service.pair_queue.running();
  snapshot.pair_workers = service.pair_queue.workers();
  snapshot.pair_cache_bytes = service.pair_scans.bytes();
  snapshot.memory_reserved_bytes = service.memory.in_use();
  exchange.reply(200, service.metrics.exposition(snapshot), kPrometheusContentType);
}

constexpr HttpRoute kRoutes[] = {
    {"POST", "/v1/register", false, check_register_headers, handle_register},
    {"POST", "/v1/register-project", false, check_register_headers, handle_register_project},
    {"GET", "/v1/version", false, nullptr, handle_version},
    {"GET", "/healthz", true, nullptr, handle_healthz},
    {"GET", "/readyz", true, nullptr, handle_readyz},
    {"GET", "/metrics", true, nullptr, handle_metrics},
    {"GET", "/openapi.json", true, nullptr, handle_openapi},
    {"GET", "/", true, nullptr, handle_page},
};

}  // namespace

std::span<const HttpRoute> http_routes() { return kRoutes; }

std::string route_name(const HttpRoute& route) { return std::string(route.method) + " " + std::string(route.path); }

}  // namespace k4reg::service
