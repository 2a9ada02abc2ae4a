// How a project registration result is shown: JSON (API field names) for scripts, a table for people, and
// the --out-dir files (NAME.pose.txt per scan, project.json).
#pragma once

#include <nlohmann/json.hpp>
#include <ostream>
#include <string>
#include <vector>

#include "k4reg/project/project_registration.h"

namespace k4reg::cli {

// files: the scans as the user named them, one per scan of the result.
nlohmann::json project_to_json(const ProjectResult& result, const std::vector<std::string>& files,
                               const ProjectParams& params);
void print_project_table(std::ostream& out, const ProjectResult& result, const std::vector<std::string>& files);

// Writes DIR/NAME.pose.txt for every scan (NAME: the file's stem; "-K" is added where two stems collide) and
// DIR/project.json; creates DIR. An unregistered scan gets no pose file (its JSON pose is null). Returns the
// pose files' names, one per scan ("" for unregistered ones).
std::vector<std::string> write_project_dir(const std::string& dir, const ProjectResult& result,
                                           const std::vector<std::string>& files, const nlohmann::json& json);

}  // namespace k4reg::cli
