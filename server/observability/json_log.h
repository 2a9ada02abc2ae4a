// Structured logs: one JSON object per line on stderr. spdlog does not escape its payload, so each line is
// built with nlohmann::json and logged with the pattern "%v".
#pragma once

#include <spdlog/common.h>

#include <nlohmann/json.hpp>
#include <string>

namespace k4reg::service {

// Replaces the default logger. `level` as in spdlog ("info", "debug", ...).
void init_json_logging(const std::string& level);

// Logs {"ts": RFC 3339 UTC with ms, "level", "msg", ...fields}.
void log_json(spdlog::level::level_enum level, const std::string& msg, nlohmann::json fields = nlohmann::json::object());

}  // namespace k4reg::service
