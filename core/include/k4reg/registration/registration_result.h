// What a pair registration returns, in three parts: the answer (the pose and how far to trust it), the
// diagnostics (what it was found from and how long each stage took) and what the QA report draws. Each part is
// its own struct so that code needing only one says so; RegistrationResult joins them with their fields at the
// top level (the proto and JSON name the same fields).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "k4reg/registration/hypothesis.h"
#include "k4reg/registration/scanner_position.h"
#include "k4reg/util/stage_timing.h"

namespace k4reg {

// Where the source goes and how far to trust it.
struct RegistrationAnswer {
  Eigen::Matrix4d transform = Eigen::Matrix4d::Identity();  // source -> target, in the files' frames
  double rmse_m = 0.0;          // RMS of the inlier residuals after refinement
  double overlap = 0.0;         // share of voxelised source points with a target neighbour after alignment
  std::size_t inliers = 0;
  // How firmly the matched surfaces pin the translation per direction, in the target's frame (trace 3; the
  // identity when surfaces face every way; see translation_constraint.h).
  Eigen::Matrix3d constraint = Eigen::Matrix3d::Zero();
  // (best - runner-up) / best, on the evidence that decided (fine geometry and intensity); small = ambiguous.
  double ambiguity_margin = 0.0;
  // The evidence cannot tell the best pose from a runner-up (margin under ambiguous_below: ambiguity_margin.h), or the
  // best pose is poorly supported: treat the transform as one of several candidates (see hypotheses).
  bool ambiguous = false;
  std::string ambiguity_reason;  // why, in words; empty when not ambiguous
  // The best pose lies on the target surface and explains what a true pose would (a pose flagged
  // ambiguous only for a close runner-up is still well supported; one flagged off the surface or poorly
  // supported is not).
  bool well_supported = false;
  std::vector<Hypothesis> hypotheses;  // best first
};

// What the answer was found from, and at what cost.
struct RegistrationDiagnostics {
  std::size_t source_points = 0, target_points = 0;
  std::size_t source_voxels = 0, target_voxels = 0;
  std::size_t source_keypoints = 0, target_keypoints = 0;
  std::string signal;           // "intensity" or "geometric" (or "voxels" for plain 4PCS)
  bool free_space_used = false;
  // Where each scan's scanner stood (file frames), and where that comes from: what the free space is seen from.
  ScannerPosition source_scanner, target_scanner;
  double min_scale_m_used = 0.0;  // the scale the result was found at
  double overlap_used = 0.0;      // the overlap whose bases found it
  int bases_tried = 0;
  std::uint64_t seed = 0;
  bool icp_converged = false;
  int icp_iterations = 0;
  std::vector<StageTiming> timings;
};

// What the QA report draws beside the clouds.
struct RegistrationQaData {
  // The points 4PCS matched (DoG keypoints, or the coarse grid of plain 4PCS) at the scale used, each in its
  // file's frame: a few thousand each.
  std::vector<Eigen::Vector3d> source_keypoint_positions_m, target_keypoint_positions_m;
};

struct RegistrationResult : RegistrationAnswer, RegistrationDiagnostics, RegistrationQaData {};

}  // namespace k4reg
