// Normal-space sampling (Rusinkiewicz and Levoy 2001): a sample whose normals cover the sphere evenly.
// An outdoor scan is mostly ground, and a sample of it as the points fall is too: on it any shift along
// the ground fits, and a plaza outvotes the monument that stands on it. Drawn evenly over normal
// directions instead, each surface orientation gets its say and what constrains the pose is heard.
// Bins: 64 of equal area on the unoriented sphere (4 bands of |n.z|, 16 sectors of azimuth); each bin
// gives as many points as it has up to a common quota, evenly spread over its points. Points without a
// normal (zero) are left out. Cost: O(n).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace k4reg {

// At most max_points of points (with their normals), in bin order.
std::vector<Eigen::Vector3f> normal_space_sample(const std::vector<Eigen::Vector3f>& points,
                                                 const std::vector<Eigen::Vector3f>& normals, std::size_t max_points);

}  // namespace k4reg
