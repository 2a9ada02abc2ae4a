// How a project registration result is shown: JSON (API field names) for scripts, a table for people, and
// the --out-dir files (NAME.pose.txt per scan, project.json).
#pragma once

#include <nlohmann/json.hpp>
#include <ostream>
#include <string>
#include <vector>

#include "k4reg/project/project_registration.h"

namespace k4reg::cli {

// Where a scan of the project came from: the file as the user named it, and its index in a multi-scan
// file (-1 when the file holds one scan).
struct ScanOrigin {
  std::string file;
  int scan = -1;
  std::string label() const;  // "file", or "file#scan"
};

nlohmann::json project_to_json(const ProjectResult& result, const std::vector<ScanOrigin>& origins,
                               const ProjectParams& params);
void print_project_table(std::ostream& out, const ProjectResult& result, const std::vector<ScanOrigin>& origins);

// Writes DIR/NAME.pose.txt for every scan (NAME: the file's stem, "-sK" for scan K of a multi-scan file; "-K"
// is added where two names collide) and
// DIR/project.json; creates DIR. An unregistered scan gets no pose file (its JSON pose is null). Returns the
// pose files' names, one per scan ("" for unregistered ones).
std::vector<std::string> write_project_dir(const std::string& dir, const ProjectResult& result,
                                           const std::vector<ScanOrigin>& origins, const nlohmann::json& json);

// Writes every registered scan to an E57 file: the cloud as read (its own frame) and its project pose, named
// after its origin. Returns how many unregistered scans were left out.
std::size_t write_project_e57(const std::string& path, const ProjectResult& result, const std::vector<PointCloud>& clouds,
                              const std::vector<ScanOrigin>& origins);

}  // namespace k4reg::cli
