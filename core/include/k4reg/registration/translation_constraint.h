// How firmly the matched surfaces pin a registration's translation, per direction (what Cyclone calls strength
// and ReCap balance). Point-to-plane ICP only measures offsets along the surface normals: a corridor's walls,
// floor and ceiling leave it free to slide along the corridor, a single wall within the wall. The final
// inliers' information Sum w n n^T, scaled to trace 3, says how much each direction is pinned against the
// average: the identity for surfaces facing every way, e^T C e = 0 along a direction nothing constrains.
// Cost: O(1); the information comes free with ICP's last accumulation.
#pragma once

#include <Eigen/Core>
#include <array>

namespace k4reg {

// information scaled to trace 3 (zero when it is zero: no inliers).
Eigen::Matrix3d normalized_constraint(const Eigen::Matrix3d& information);

// The constraint along each axis of its frame: the diagonal.
std::array<double, 3> axis_constraint(const Eigen::Matrix3d& constraint);

// Along the least constrained direction: the smallest eigenvalue (0-1; 1 only for the identity).
double weakest_constraint(const Eigen::Matrix3d& constraint);

// The same constraint in another frame: rotation * constraint * rotation^T, where rotation maps its frame into
// the other.
Eigen::Matrix3d rotated_constraint(const Eigen::Matrix3d& constraint, const Eigen::Matrix3d& rotation);

}  // namespace k4reg
