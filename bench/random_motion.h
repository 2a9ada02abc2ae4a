// Real scans moved by a random rigid motion, as a user's scans in arbitrary scanner frames would be
// (shared by the benchmarks that register real data sets blind).
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "k4reg/geometry/point_cloud.h"

namespace k4reg::bench {

// A uniform random rotation and a translation of up to `reach` per axis, from `seed`.
Eigen::Matrix4d random_motion(std::uint64_t seed, double reach);

// The cloud with every point moved by m (survey-sized coordinates keep their precision).
PointCloud moved(const PointCloud& cloud, const Eigen::Matrix4d& m);

}  // namespace k4reg::bench
