// What a scan's own sampling says about the scale to register it at: how far apart its points are and
// how large the scene is, both blind to a few stray returns (max-range hits, dust, a passer-by).
// This is where the automatic minimum scale starts and where it stops stepping down.
// Cost: O(m log m) on a subsample of m <= 20 000 points, whatever the cloud's size.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "k4reg/geometry/point_cloud.h"

namespace k4reg {

struct Sampling {
  double spacing_m = 0.0;   // typical distance between neighbouring points (the step of a grid as dense)
  double diameter_m = 0.0;  // robust extent: diagonal of the 2nd..98th percentile box
};

// Robust extent of a point set: the diagonal of its 2nd..98th percentile box per axis.
double robust_diameter(const std::vector<Eigen::Vector3f>& points);

// Measured on a random subsample of at most 20 000 points (all of them for smaller clouds), whose
// neighbour distances are scaled back to the full cloud's density; see sampling.cpp. The spacing is
// that of a grid of the same density (its step). Zero for fewer than 2 points.
Sampling measure_sampling(const PointCloud& cloud);

}  // namespace k4reg
