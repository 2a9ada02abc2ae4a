#include "k4reg/geometry/sampling.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "k4reg/geometry/neighbor_grid.h"

namespace k4reg {
namespace {

constexpr std::size_t kSamplePoints = 20000;  // enough for a median to within a few per cent

// m points drawn at random (fixed seed; repeats dropped). Scans are stored in scan order, so every
// k-th point would keep whole scan lines and drop others: its neighbour distances follow the lines.
std::vector<Eigen::Vector3f> random_subsample(const std::vector<Eigen::Vector3f>& points, std::size_t count) {
  if (points.size() <= count) return points;
  std::mt19937_64 rng(1);
  std::uniform_int_distribution<std::size_t> pick(0, points.size() - 1);
  std::vector<std::size_t> indices(count);
  for (std::size_t& i : indices) i = pick(rng);
  std::sort(indices.begin(), indices.end());
  indices.erase(std::unique(indices.begin(), indices.end()), indices.end());
  std::vector<Eigen::Vector3f> sample;
  sample.reserve(indices.size());
  for (const std::size_t i : indices) sample.push_back(points[i]);
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
  const std::vector<Eigen::Vector3f> sample = random_subsample(cloud.points, kSamplePoints);
  out.diameter_m = robust_diameter(sample);
  if (!(out.diameter_m > 0.0)) return out;
  // Cells of a few typical neighbour distances of the subsample (a surface of this extent holding m points).
  const double cell_m = 4.0 * out.diameter_m / std::sqrt(static_cast<double>(sample.size()));
  const NeighborGrid grid(sample, cell_m);
  // In parallel: near a scanner a cell holds thousands of the sample's points.
  std::vector<float> nearest(sample.size(), std::numeric_limits<float>::max());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, sample.size(), 512), [&](const auto& range) {
    for (std::size_t i = range.begin(); i != range.end(); ++i)
      grid.nearest_within(sample[i], static_cast<float>(cell_m), &nearest[i],
                          [&](std::uint32_t k, float d2) { return k != i && d2 > 0.0f; });  // duplicates say nothing
  });
  std::erase(nearest, std::numeric_limits<float>::max());
  for (float& d : nearest) d = std::sqrt(d);
  if (nearest.empty()) return out;
  std::nth_element(nearest.begin(), nearest.begin() + nearest.size() / 2, nearest.end());
  const double median = nearest[nearest.size() / 2];
  if (sample.size() == cloud.size()) {
    out.spacing_m = median;
  } else {
    // A random subsample of a surface is a Poisson process of density rho * m / n, whose median
    // nearest-neighbour distance is sqrt(ln 2 / pi) / sqrt(density): the full cloud's spacing
    // 1 / sqrt(rho) (a grid's step) follows.
    const double kept = static_cast<double>(sample.size()) / static_cast<double>(cloud.size());
    out.spacing_m = median * std::sqrt(kept) / std::sqrt(std::log(2.0) / M_PI);
  }
  return out;
}

}  // namespace k4reg
