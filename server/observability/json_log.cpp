#include "observability/json_log.h"

#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <ctime>
#include <fmt/format.h>

namespace k4reg::service {
namespace {

std::string utc_timestamp() {
  const auto now = std::chrono::system_clock::now();
  const std::time_t seconds = std::chrono::system_clock::to_time_t(now);
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  std::tm tm{};
  gmtime_r(&seconds, &tm);
  return fmt::format("{:04}-{:02}-{:02}T{:02}:{:02}:{:02}.{:03}Z", tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday,
                     tm.tm_hour, tm.tm_min, tm.tm_sec, ms);
}

}  // namespace

void init_json_logging(const std::string& level) {
  auto logger = spdlog::stderr_logger_mt("k4reg-server");
  logger->set_pattern("%v");
  logger->set_level(spdlog::level::from_str(level));
  logger->flush_on(spdlog::level::trace);  // log lines must not sit in a buffer when the pod dies
  spdlog::set_default_logger(logger);
}

void log_json(spdlog::level::level_enum level, const std::string& msg, nlohmann::json fields) {
  if (!spdlog::should_log(level)) return;
  // Ordered: ts, level and msg lead every line, the call's own fields follow.
  const auto level_name = spdlog::level::to_string_view(level);
  nlohmann::ordered_json line{
      {"ts", utc_timestamp()}, {"level", std::string(level_name.data(), level_name.size())}, {"msg", msg}};
  for (auto& [key, value] : fields.items()) line[key] = std::move(value);
  // Client-supplied strings (file names, ids) may not be UTF-8: replace rather than throw.
  spdlog::log(level, "{}", line.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
}

}  // namespace k4reg::service
