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
#include "k4reg/registration/scanner_position.h"
#include "k4reg/util/stage_timing.h"

namespace k4reg {

enum class CoarseMethod {
  kKeypoint4pcs,  // K-4PCS: 4PCS on DoG keypoints (the paper's method)
  kPlain4pcs,     // baseline: 4PCS on a coarser voxel grid (the paper's Sec. 3.1)
};

enum class KeypointSignal {
  kAuto,        // intensity when both clouds have it (geometric too if its pose is weak), else geometric
  kIntensity,   // DoG of the (voxel-averaged) intensity
  kGeometric,   // DoG of the surface variation from local PCA (clouds without intensity)
};

enum class FreeSpaceCheck {
  kAuto,  // on when both scans have a terrestrial scanner position (scanner_position.h: from the file, the frame's
          // origin or the scan's sampling), or are single views of an object by a range camera (single_view.h: seen
          // along their viewing direction)
  kOn,    // from the scanner positions known, else the frames' origins
  kOff,
};

struct RegistrationParams {
  // The two parameters that matter (paper Tab. 1); 0 = found from the data (the default).
  // min_scale_m: minimum DoG scale sigma, also the voxel grid spacing. Automatic: the scans' robust
  // diameter / 128 (at least twice their point spacing). Given or not, a scale that yields too few
  // keypoints or no well-supported pose is halved, down to the point spacing (at most 4 scales).
  double min_scale_m = 0.0;
  // overlap: approximate overlap of the two scans, (0, 1]; it sets the number and width of the 4PCS
  // bases. Automatic: rounds of fresh bases for an overlap of 0.8, 0.6, then 0.4, until a pose is well
  // supported.
  double overlap = 0.0;

  // DoG detector (paper Tab. 1 defaults).
  int octaves = 5;
  int scales_per_octave = 5;
  double min_contrast = 0.01;  // fraction of the signal's range
  KeypointSignal signal = KeypointSignal::kAuto;

  // 4PCS.
  CoarseMethod method = CoarseMethod::kKeypoint4pcs;
  double plain_voxel_m = 0.0;  // voxel spacing for kPlain4pcs; 0 = chosen to give ~ as many points as keypoints
  int max_bases = 0;           // number of 4-point bases L; 0 = from the overlap
  int hypotheses_kept = 5;     // distinct hypotheses re-scored by the symmetry guard
  // Penalise hypotheses that put source points where the target scanner (at the target file's origin)
  // saw empty space: breaks the 180-degree flips of symmetric rooms.
  FreeSpaceCheck free_space = FreeSpaceCheck::kAuto;

  // Levelled scanners (a tilt compensator makes their z axes vertical): only rotations about z are searched and
  // refined, so no out-of-plane flip can win, and fewer 4PCS sets pass the fit. Every transform is then a
  // rotation about z and a translation. Wrong for tilted scans (a handheld or mobile scanner).
  bool levelled = false;

  // Where a scale finds no well-supported pose, search the pair again with the scans swapped (4PCS draws its
  // bases in the source) and keep a pose found there if it is well supported from the source's side too.
  // A project turns it off for its pairs: its loops confirm a link found from either side, and it searches
  // the pairs of scans no loop confirms from the other side itself.
  bool search_other_side = true;

  // ICP refinement.
  bool icp = true;
  int icp_max_iterations = 50;

  std::uint64_t seed = 42;
  int threads = 0;             // 0 = all cores
  double time_budget_s = 0.0;  // 0 = unlimited; otherwise kDeadlineExceeded after this long (at most 1e9)
};

struct Hypothesis {
  Eigen::Matrix4d transform = Eigen::Matrix4d::Identity();  // source -> target
  double keypoint_score = 0.0;  // share of source keypoints with a target keypoint in tolerance
  double cloud_score = 0.0;     // share of voxelised source points with a target point in tolerance
  // After a full refinement (leading hypotheses only; 0 otherwise): the cloud score again, and the share
  // of the source points near the target surface that lie on it, within half the minimum scale
  // (pose_score.h). A true pose puts them on it; a wrong one only touches it.
  double refined_score = 0.0;
  double surface_agreement = 0.0;
  // The 4-point base it came from (source file frame) and the congruent set 4PCS matched it to (target file
  // frame), for looking at (the QA report); empty for the symmetric twins the symmetry guard adds.
  std::vector<Eigen::Vector3d> base_source_m, base_target_m;
};

// A refined pose with less surface agreement than this share of what the target's own two halves reach
// (PreparedScan::surface_self_agreement: 0.99 or more on clean scans, less on noisy ones) is not taken as well
// supported.
constexpr double kMinSurfaceAgreement = 0.75;

// Below this margin between the best pose and the runner-up, a result judged with free space is flagged ambiguous
// (on geometry alone it needs more: ambiguity_margin.h).
constexpr double kAmbiguousMargin = 0.05;

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
