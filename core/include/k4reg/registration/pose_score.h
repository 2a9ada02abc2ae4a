// Judging the leading poses after a full refinement (beyond the paper), on two kinds of evidence.
// - Support: each pose is scored again with cloud_score on the guard's stage (twice the finest spacing,
//   tolerance 1.5 of its voxels). A true pose and its symmetric twin can land within a few per cent of
//   each other after the guard's short settle; only the full ICP brings each to its own optimum. The
//   finest stage is no better for this, as far surfaces seen at grazing incidence are sampled more
//   sparsely than its tolerance, which favours the pose that puts one scanner where the other stood.
// - Surface agreement: of the finest stage's source points that come near the target surface (within
//   two voxels), the share that lie on it (point-to-plane within half a voxel). A true pose puts them on
//   it to the precision of the voxel centroids; a wrong pose that ICP has pulled into contact only
//   touches it, its near points spread over the band (a uniform spread gives 0.25). Point-to-plane, so
//   sparse sampling of far surfaces does not lower it. It cannot tell a symmetric twin (that lies on the
//   surface too): support and free space do that.
// Cost per pose: one nearest-neighbour look-up per scored point (at most 100 000 per measure).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "k4reg/registration/icp.h"
#include "k4reg/registration/symmetry_guard.h"

namespace k4reg {

// Of `points` under t that come within two voxels of the reference stage's surface, the share that lie on it
// (point-to-plane within half a voxel); 0 when none come near. reference: a target stage (grid and normals).
double surface_agreement(const std::vector<Eigen::Vector3f>& points, const Eigen::Matrix4d& t,
                         const IcpPyramid::Stage& reference);

class PoseScorer {
 public:
  // Pyramids in local frames, with at least two stages; views may be null (no free-space test).
  PoseScorer(const IcpPyramid& source, const IcpPyramid& target, const ScanViews* views, double overlap);
  // cloud_score of the source under t (source -> target).
  double score(const Eigen::Matrix4d& t) const;
  // The share of near source points on the target surface under t; 0 when none come near.
  double surface_agreement(const Eigen::Matrix4d& t) const;

 private:
  ScoredSource scored_;                  // an even subsample of the source's guard stage
  std::vector<Eigen::Vector3f> finest_;  // an even subsample of the source's finest stage
  const IcpPyramid::Stage& reference_;
  const IcpPyramid::Stage& finest_reference_;
  const ScanViews* views_;
  double overlap_;
  float tau_;
};

}  // namespace k4reg
