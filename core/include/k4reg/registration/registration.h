// K-4PCS pairwise registration (Theiler, Wegner, Schindler 2014), top to bottom:
//   voxel grid (centroids, spacing = min scale)  ->  3D DoG keypoints  ->  keypoint 4PCS
//   ->  symmetry guard (re-score the best distinct hypotheses on the voxelised clouds)  ->  ICP;
//   where a scale finds no well-supported pose: the same with the scans swapped, its pose judged again from the
//   source's side; then the next, finer scale.
// Cost: linear in the input points for the voxel grid; the rest depends on the voxel / keypoint counts.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "k4reg/util/cancellation.h"
#include "k4reg/geometry/point_cloud.h"
#include "k4reg/registration/ambiguity_margin.h"
#include "k4reg/registration/hypothesis.h"
#include "k4reg/registration/registration_params.h"
#include "k4reg/registration/scanner_position.h"
#include "k4reg/util/stage_timing.h"

namespace k4reg {

// A refined pose with less surface agreement than this share of what the target's own two halves reach
// (PreparedScan::surface_self_agreement: 0.99 or more on clean scans, less on noisy ones) is not taken as well
// supported.
constexpr double kMinSurfaceAgreement = 0.75;

struct RegistrationResult {
  Eigen::Matrix4d transform = Eigen::Matrix4d::Identity();  // source -> target, in the files' frames
  double rmse_m = 0.0;          // RMS of the inlier residuals after refinement
  double overlap = 0.0;         // share of voxelised source points with a target neighbour after alignment
  std::size_t inliers = 0;
  // How firmly the matched surfaces pin the translation per direction, in the target's frame (trace 3; the
  // identity when surfaces face every way; see translation_constraint.h).
  Eigen::Matrix3d constraint = Eigen::Matrix3d::Zero();
  std::size_t source_points = 0, target_points = 0;
  std::size_t source_voxels = 0, target_voxels = 0;
  std::size_t source_keypoints = 0, target_keypoints = 0;
  std::string signal;           // "intensity" or "geometric" (or "voxels" for plain 4PCS)
  bool free_space_used = false;
  // Where each scan's scanner stood (file frames), and where that comes from: what the free space is seen from.
  ScannerPosition source_scanner, target_scanner;
  double min_scale_m_used = 0.0;  // the scale the result was found at
  double overlap_used = 0.0;      // the overlap whose bases found it
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
  // The points 4PCS matched (DoG keypoints, or the coarse grid of plain 4PCS) at the scale used, each in its
  // file's frame: for looking at (the QA report), a few thousand each.
  std::vector<Eigen::Vector3d> source_keypoint_positions_m, target_keypoint_positions_m;
  int bases_tried = 0;
  std::uint64_t seed = 0;
  bool icp_converged = false;
  int icp_iterations = 0;
  std::vector<StageTiming> timings;
};

// Throws kInvalidArgument naming the first parameter out of range.
void validate(const RegistrationParams& params);

// Registers source onto target. Throws k4reg::Error: kInvalidArgument for empty/degenerate clouds or
// parameters out of range, kFailedPrecondition when too few keypoints or no hypothesis is found,
// kCancelled / kDeadlineExceeded when stopped. Thread-safe: independent calls may run concurrently.
// Deterministic: the same inputs and seed give the same transform for any thread count.
RegistrationResult register_clouds(const PointCloud& source, const PointCloud& target,
                                   const RegistrationParams& params, const CancellationToken* cancel = nullptr,
                                   const ProgressCallback& progress = {});

class PreparedScan;  // prepared_scan.h
// The same on prepared scans, reusing (and adding to) the work already done on each: a project registers each
// scan in many pairs. The result equals register_clouds on the two clouds, bit for bit.
RegistrationResult register_clouds(const PreparedScan& source, const PreparedScan& target,
                                   const RegistrationParams& params, const CancellationToken* cancel = nullptr,
                                   const ProgressCallback& progress = {});

// The scale register_clouds starts from: min_scale_m when given (> 0), else the automatic start from the two
// scans' sampling. Throws kInvalidArgument when the clouds have no extent. Cost: measures their sampling once.
double starting_scale_m(const PreparedScan& source, const PreparedScan& target, double min_scale_m);

// Judges given poses (source -> target, files' frames) as register_clouds judges the hypotheses it finds, at
// one scale: the symmetry guard (which adds their symmetric twins), the leading poses' full refinement and
// the verdict, with the same figures and flags. For poses found elsewhere: a project's loops propose poses a
// pair's own 4PCS missed. At params.min_scale_m, or where it is 0 at the scale register_clouds starts from
// (not at a finer scale a pair may have stepped down to: there the tolerances are finer than the sampling of
// far surfaces, and a true pose can score 0.34); params.overlap must be set.
// Cost: the guard and the verdict of one registration, without keypoints or 4PCS.
RegistrationResult judge_poses(const PreparedScan& source, const PreparedScan& target, const RegistrationParams& params,
                               const std::vector<Eigen::Matrix4d>& poses, const CancellationToken* cancel = nullptr);

}  // namespace k4reg
