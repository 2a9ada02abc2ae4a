// Open3D's global registration (bench/open3d_pair.py) on one pair, run from the comparison's worker as a
// child process: Open3D 0.16 ships for Python only on Debian 12 (python3-open3d). The clouds go over as
// float PLY files of their local-frame points, exactly the points PCL's methods get.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace k4reg::bench {

// "" when /usr/bin/python3 finds the open3d module and the script is in place, otherwise why Open3D's
// methods cannot run (the comparison skips them).
std::string open3d_unavailable_reason();

struct Open3dPair {
  Eigen::Matrix4d transform = Eigen::Matrix4d::Identity();  // source local -> target local
  double seconds = 0;  // the script's own clock: both clouds in memory -> transform
  double wall_s = 0;   // the whole call: writing the files, Python start-up and import, reading, the answer
  std::map<std::string, double> stages;
  std::size_t source_points = 0, target_points = 0;  // after Open3D's voxel down-sampling
  bool timed_out = false;                            // killed at time_limit_s: no transform
};

// method: "ransac" or "fgr" (open3d_pair.py --method). Throws std::runtime_error when the child fails.
Open3dPair open3d_pair(const std::vector<Eigen::Vector3f>& source, const std::vector<Eigen::Vector3f>& target,
                       const std::string& method, double voxel_m, std::uint64_t seed, int threads, double time_limit_s);

}  // namespace k4reg::bench
