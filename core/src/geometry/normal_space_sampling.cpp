#include "k4reg/geometry/normal_space_sampling.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace k4reg {
namespace {

constexpr int kBands = 4, kSectors = 16;  // |n.z| is uniform on the sphere: equal bands are equal areas

int bin_of(Eigen::Vector3f n) {
  if (n.z() < 0) n = -n;
  const int band = std::min(kBands - 1, static_cast<int>(n.z() * kBands));
  const float turn = (std::atan2(n.y(), n.x()) + static_cast<float>(M_PI)) / static_cast<float>(2.0 * M_PI);
  const int sector = std::clamp(static_cast<int>(turn * kSectors), 0, kSectors - 1);
  return band * kSectors + sector;
}

}  // namespace

std::vector<Eigen::Vector3f> normal_space_sample(const std::vector<Eigen::Vector3f>& points,
                                                 const std::vector<Eigen::Vector3f>& normals, std::size_t max_points) {
  std::array<std::vector<std::size_t>, kBands * kSectors> bins;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!normals[i].isZero()) bins[bin_of(normals[i])].push_back(i);
  // The largest common quota that keeps the sample within max_points (full bins give all they have).
  auto total = [&](std::size_t quota) {
    std::size_t n = 0;
    for (const auto& bin : bins) n += std::min(bin.size(), quota);
    return n;
  };
  std::size_t low = 0, high = max_points;
  while (low < high) {
    const std::size_t mid = (low + high + 1) / 2;
    if (total(mid) <= max_points)
      low = mid;
    else
      high = mid - 1;
  }
  std::vector<Eigen::Vector3f> sample;
  sample.reserve(total(low));
  for (const auto& bin : bins) {
    const std::size_t take = std::min(bin.size(), low);
    for (std::size_t k = 0; k < take; ++k) sample.push_back(points[bin[k * bin.size() / take]]);
  }
  return sample;
}

}  // namespace k4reg
