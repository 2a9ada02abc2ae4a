#include "k4reg/sampling.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "k4reg/neighbor_grid.h"

namespace k4reg {
namespace {

constexpr std::size_t kSamplePoints = 20000;  // enough for a median to within a few per cent

std::vector<Eigen::Vector3f> even_subsample(const std::vector<Eigen::Vector3f>& points, std::size_t count) {
  const std::size_t step = std::max<std::size_t>(1, points.size() / count);
  std::vector<Eigen::Vector3f> sample;
  sample.reserve(points.size() / step + 1);
  for (std::size_t i = 0; i < points.size(); i += step) sample.push_back(points[i]);
  return sample;
}

}  // namespace

double robust_diameter(const std::vector<Eigen::Vector3f>& points) {
  Eigen::Vector3d extent;
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<float> v(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) v[i] = points[i][axis];
    const std::size_t lo = v.size() / 50, hi = v.size() - 1 - v.size() / 50;
    std::nth_element(v.begin(), v.begin() + lo, v.end());
    const float low = v[lo];
    std::nth_element(v.begin(), v.begin() + hi, v.end());
    extent[axis] = v[hi] - low;
  }
  return extent.norm();
}

Sampling measure_sampling(const PointCloud& cloud) {
  Sampling out;
  if (cloud.size() < 2) return out;
  const std::vector<Eigen::Vector3f> sample = even_subsample(cloud.points, kSamplePoints);
  out.diameter_m = robust_diameter(sample);
  if (!(out.diameter_m > 0.0)) return out;
  // Cells of a few typical neighbour distances of the subsample (a surface of this extent holding m points).
  const double cell_m = 4.0 * out.diameter_m / std::sqrt(static_cast<double>(sample.size()));
  const NeighborGrid grid(sample, cell_m);
  std::vector<float> nearest;
  nearest.reserve(sample.size());
  for (std::size_t i = 0; i < sample.size(); ++i) {
    float best = std::numeric_limits<float>::max();
    grid.for_each_within(sample[i], static_cast<float>(cell_m), [&](std::uint32_t k, float d2) {
      if (k != i && d2 > 0.0f) best = std::min(best, d2);  // duplicates say nothing about the spacing
    });
    if (best < std::numeric_limits<float>::max()) nearest.push_back(std::sqrt(best));
  }
  if (nearest.empty()) return out;
  std::nth_element(nearest.begin(), nearest.begin() + nearest.size() / 2, nearest.end());
  const double kept = static_cast<double>(sample.size()) / static_cast<double>(cloud.size());
  out.spacing_m = nearest[nearest.size() / 2] * std::sqrt(kept);
  return out;
}

}  // namespace k4reg
