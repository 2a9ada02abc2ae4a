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
#include "k4reg/registration/registration_result.h"

namespace k4reg {

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
