// How a registration result is shown: a readable table for people, JSON (API field names) for scripts.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>

#include "k4reg/registration/metrics.h"
#include "k4reg/registration/registration.h"

namespace k4reg::cli {

// A 4x4 matrix as 16 numbers, row-major (the API's layout).
nlohmann::json matrix_to_json(const Eigen::Matrix4d& m);

// Points as 3 numbers each, one after the other (the API's layout).
nlohmann::json points_to_json(const std::vector<Eigen::Vector3d>& points);

nlohmann::json result_to_json(const RegistrationResult& result);
// Stage timings: [{"stage", "seconds"}], and as indented lines with their total.
nlohmann::json timings_to_json(const std::vector<StageTiming>& timings);
void print_timings(std::ostream& out, const std::vector<StageTiming>& timings);
void print_result_table(std::ostream& out, const RegistrationResult& result);

nlohmann::json error_to_json(const TransformError& error, bool success);
void print_error_table(std::ostream& out, const TransformError& error, bool success);

}  // namespace k4reg::cli
