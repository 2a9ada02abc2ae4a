// What a scan's own sampling says about the scale to register it at: how far apart its points are and
// how large the scene is, both blind to a few stray returns (max-range hits, dust, a passer-by).
// This is where the automatic minimum scale starts and where it stops stepping down.
// Cost: O(n) to pick a fixed-size subsample, then O(m log m) on it (m <= 20 000 points).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "k4reg/point_cloud.h"

namespace k4reg {

struct Sampling {
  double spacing_m = 0.0;   // typical distance between neighbouring points (median nearest-neighbour distance)
  double diameter_m = 0.0;  // robust extent: diagonal of the 2nd..98th percentile box
};

// Robust extent of a point set: the diagonal of its 2nd..98th percentile box per axis.
double robust_diameter(const std::vector<Eigen::Vector3f>& points);

// Measured on an even subsample (every k-th point). The nearest-neighbour distance of a subsample of
// m of n surface points is sqrt(n / m) times that of the full cloud (the density of a surface scales
// with the share of points kept), which is how the spacing is scaled back. Zero for fewer than 2 points.
Sampling measure_sampling(const PointCloud& cloud);

}  // namespace k4reg
