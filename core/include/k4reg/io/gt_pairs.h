// Ground-truth pair files (gt_pairs.log) shipped with the test data sets.
//
// Format: lines starting with '#' (and blank lines) are comments. Each record is one line
// `source target overlap inlier_rmse` followed by 4 lines of 4 numbers: the row-major 4x4 matrix
// T_target_source (p_target = T * p_source). Any malformed record is a k4reg::Error (kInvalidArgument,
// kNotFound for a missing file) naming the file and line.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace k4reg {

struct GtPair {
  std::string source, target;  // file names as written in the log (relative to the log's folder)
  double overlap = 0.0;        // fraction of source points near the target after applying T
  double inlier_rmse = 0.0;    // RMS of those distances, metres
  Eigen::Matrix4d T_target_source = Eigen::Matrix4d::Identity();
};

std::vector<GtPair> read_gt_pairs(const std::string& path);

}  // namespace k4reg
