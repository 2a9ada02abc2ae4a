// How a registration result is shown: a readable table for people, JSON (API field names) for scripts.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>

#include "k4reg/metrics.h"
#include "k4reg/registration.h"

namespace k4reg::cli {

nlohmann::json result_to_json(const RegistrationResult& result);
void print_result_table(std::ostream& out, const RegistrationResult& result);

nlohmann::json error_to_json(const TransformError& error, bool success);
void print_error_table(std::ostream& out, const TransformError& error, bool success);

}  // namespace k4reg::cli
