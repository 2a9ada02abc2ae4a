// Judging the leading poses after a full refinement (beyond the paper). The symmetry guard scores
// hypotheses after a short settle; a true pose and its symmetric twin can land within a few per cent of
// each other there, and only the full ICP brings each to its own optimum. Each leading hypothesis is
// then scored again on the guard's stage (twice the finest spacing, tolerance 1.5 of its voxels): the
// finest stage is no better, as far surfaces seen at grazing incidence are sampled more sparsely than
// its tolerance, which favours the pose that puts one scanner where the other stood.
// Cost per pose: one nearest-neighbour look-up per scored point (at most 100 000 of them).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "k4reg/icp.h"
#include "k4reg/symmetry_guard.h"

namespace k4reg {

class PoseScorer {
 public:
  // Pyramids in local frames, with at least two stages; views may be null (no free-space test).
  PoseScorer(const IcpPyramid& source, const IcpPyramid& target, const ScanViews* views, double overlap);
  // cloud_score of the source under t (source -> target).
  double score(const Eigen::Matrix4d& t) const;

 private:
  std::vector<Eigen::Vector3f> scored_;  // an even subsample of the source's stage
  const IcpPyramid::Stage& reference_;
  const ScanViews* views_;
  double overlap_;
  float tau_;
};

}  // namespace k4reg
