// A candidate pose of a pair, as 4PCS finds it and the symmetry guard and the verdict score it: what the steps of a
// registration pass each other (four_pcs.h, symmetry_guard.h) and its result lists (registration.h).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace k4reg {

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

}  // namespace k4reg
