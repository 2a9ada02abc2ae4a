#include "observability/request_log.h"

#include "status_name.h"

#include <fmt/format.h>

#include <algorithm>
#include <random>

#include "observability/json_log.h"

namespace k4reg::service {
namespace {

std::string new_uuid() {
  thread_local std::mt19937_64 random{std::random_device{}()};
  const std::uint64_t hi = (random() & 0xFFFFFFFFFFFF0FFFull) | 0x4000ull;                 // version 4
  const std::uint64_t lo = (random() & 0x3FFFFFFFFFFFFFFFull) | 0x8000000000000000ull;    // variant 10
  return fmt::format("{:08x}-{:04x}-{:04x}-{:04x}-{:012x}", hi >> 32, (hi >> 16) & 0xFFFF, hi & 0xFFFF, lo >> 48,
                     lo & 0xFFFFFFFFFFFFull);
}

}  // namespace

std::string request_id_or_new(std::string_view offered) {
  if (!offered.empty() && offered.size() <= 128 &&
      std::all_of(offered.begin(), offered.end(), [](char c) { return c > 0x20 && c < 0x7F && c != '"' && c != '\\'; }))
    return std::string(offered);
  return new_uuid();
}

RequestRecord open_request(grpc::CallbackServerContext& context, const char* method) {
  RequestRecord record;
  record.method = method;
  const auto& metadata = context.client_metadata();
  const auto offered = metadata.find("x-request-id");
  record.request_id = request_id_or_new(offered == metadata.end() ? std::string_view()
                                                                  : std::string_view(offered->second.data(), offered->second.size()));
  record.peer = context.peer();
  context.AddInitialMetadata("x-request-id", record.request_id);
  return record;
}

void log_request(const RequestRecord& r) {
  const double duration_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - r.start).count();
  nlohmann::json fields{{"request_id", r.request_id},
                        {"protocol", r.protocol},
                        {"method", r.method},
                        {"peer", r.peer},
                        {"code", status_code_name(r.code)},
                        {"duration_ms", duration_ms},
                        {"source_points", r.source_points},
                        {"target_points", r.target_points},
                        {"queue_wait_ms", 1000.0 * r.queue_wait_s},
                        {"registration_ms", 1000.0 * r.registration_s}};
  if (r.http_status) fields["http_status"] = r.http_status;
  if (r.upload_bytes) fields["upload_bytes"] = r.upload_bytes;
  if (r.code != grpc::StatusCode::OK) fields["error"] = r.error;
  // Client mistakes and overload are expected traffic; only server faults are warnings.
  const bool fault = r.code == grpc::StatusCode::INTERNAL || r.code == grpc::StatusCode::UNKNOWN;
  const auto level = fault ? spdlog::level::warn : r.probe ? spdlog::level::debug : spdlog::level::info;
  log_json(level, "request", std::move(fields));
}

}  // namespace k4reg::service
