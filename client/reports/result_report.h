// How a registration result is shown: a readable table for people, JSON (API field names) for scripts.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>

#include "k4reg/registration/metrics.h"
#include "k4reg/registration/registration.h"

namespace k4reg::cli {

// A 4x4 matrix as 16 numbers, row-major (the API's layout).
nlohmann::json matrix_to_json(const Eigen::Matrix4d& m);

// Points as 3 numbers each, one after the other (the API's layout).
nlohmann::json points_to_json(const std::vector<Eigen::Vector3d>& points);

// Where a scan's scanner stood: {"point_m", "source", "fit", "angular_step_rad", "reason"}, and one line.
nlohmann::json scanner_to_json(const ScannerPosition& scanner);
std::string scanner_to_text(const ScannerPosition& scanner);

nlohmann::json result_to_json(const RegistrationResult& result);
// Stage timings: [{"stage", "seconds"}], and as indented lines with their total.
nlohmann::json timings_to_json(const std::vector<StageTiming>& timings);
void print_timings(std::ostream& out, const std::vector<StageTiming>& timings);
void print_result_table(std::ostream& out, const RegistrationResult& result);

nlohmann::json error_to_json(const TransformError& error, bool success);
void print_error_table(std::ostream& out, const TransformError& error, bool success);

}  // namespace k4reg::cli
