#include "open3d_peer.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "child_process.h"
#include "k4reg/geometry/point_cloud.h"
#include "k4reg/io/ply_io.h"
#include "k4reg/util/stopwatch.h"

namespace fs = std::filesystem;

namespace k4reg::bench {
namespace {

// Debian's python3-open3d is installed for the system interpreter only (a pyenv python3 on PATH lacks it).
constexpr const char* kPython = "/usr/bin/python3";

std::string script_path() { return std::string(K4REG_BENCH_SOURCE_DIR) + "/open3d_pair.py"; }

// A private folder for the two files, removed with everything in it however the call ends.
class TempFolder {
 public:
  TempFolder() {
    std::string pattern = (fs::temp_directory_path() / "k4reg-open3d-XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw std::runtime_error("cannot create a temporary folder in " + pattern);
    path_ = pattern;
  }
  ~TempFolder() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  TempFolder(const TempFolder&) = delete;
  TempFolder& operator=(const TempFolder&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

void write_points(const fs::path& path, const std::vector<Eigen::Vector3f>& points) {
  PointCloud cloud;  // origin zero: write_ply stores float coordinates
  cloud.points = points;
  write_ply(path.string(), cloud);
}

}  // namespace

std::string open3d_unavailable_reason() {
  if (!fs::exists(script_path())) return script_path() + " is missing";
  try {
    const ChildOutcome probe = run_child(
        {kPython, "-c", "import importlib.util, sys; sys.exit(importlib.util.find_spec('open3d') is None)"}, 60.0);
    if (probe.exit_code != 0) return "python3-open3d is not installed (apt-get install python3-open3d)";
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

Open3dPair open3d_pair(const std::vector<Eigen::Vector3f>& source, const std::vector<Eigen::Vector3f>& target,
                       const std::string& method, double voxel_m, std::uint64_t seed, int threads,
                       double time_limit_s) {
  const auto start = SteadyClock::now();
  const TempFolder folder;
  const fs::path source_file = folder.path() / "source.ply", target_file = folder.path() / "target.ply";
  write_points(source_file, source);
  write_points(target_file, target);
  char voxel[32];
  std::snprintf(voxel, sizeof voxel, "%.9g", voxel_m);
  const ChildOutcome child =
      run_child({"/usr/bin/env", "OMP_NUM_THREADS=" + std::to_string(threads), kPython, script_path(), "--method",
                 method, "--voxel", voxel, "--seed", std::to_string(seed), source_file.string(), target_file.string()},
                time_limit_s);
  Open3dPair out;
  out.wall_s = seconds_since(start);
  if (child.timed_out) {
    out.timed_out = true;
    return out;
  }
  if (child.exit_code != 0 || child.output.empty())
    throw std::runtime_error("open3d_pair.py failed (exit " + std::to_string(child.exit_code) + ", signal " +
                             std::to_string(child.signal) + ")");
  const std::size_t line = child.output.rfind("\n{", child.output.size() - 1);  // the answer is the last line
  const nlohmann::json r = nlohmann::json::parse(child.output.substr(line == std::string::npos ? 0 : line + 1));
  const auto row_major = r.at("transform").get<std::vector<double>>();
  if (row_major.size() != 16) throw std::runtime_error("open3d_pair.py: the transform needs 16 numbers");
  out.transform = Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(row_major.data());
  out.seconds = r.at("seconds");
  out.stages = r.at("stages").get<std::map<std::string, double>>();
  out.source_points = r.at("source_points");
  out.target_points = r.at("target_points");
  return out;
}

}  // namespace k4reg::bench
