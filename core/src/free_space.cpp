#include "k4reg/free_space.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace k4reg {
namespace {

// Half-degree cells: about 9 cm at 10 m, coarse enough that voxelised scans fill them.
constexpr int kAzimuthCells = 720, kElevationCells = 360;

}  // namespace

FreeSpaceImage::FreeSpaceImage(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& scanner_m,
                               double margin_m)
    : scanner_(scanner_m),
      margin_(static_cast<float>(margin_m)),
      nearest_(kAzimuthCells * kElevationCells, std::numeric_limits<float>::infinity()) {
  for (const Eigen::Vector3f& p : points) {
    const Eigen::Vector3f d = p - scanner_;
    const float range = d.norm();
    if (range <= 0) continue;
    float& nearest = nearest_[cell(d / range)];
    nearest = std::min(nearest, range);
  }
}

int FreeSpaceImage::cell(const Eigen::Vector3f& u) const {
  const float azimuth = std::atan2(u.y(), u.x()) + static_cast<float>(M_PI);      // [0, 2 pi]
  const float elevation = std::acos(std::clamp(u.z(), -1.0f, 1.0f));               // [0, pi]
  const int a = std::min(kAzimuthCells - 1, static_cast<int>(azimuth * (kAzimuthCells / (2 * M_PI))));
  const int e = std::min(kElevationCells - 1, static_cast<int>(elevation * (kElevationCells / M_PI)));
  return e * kAzimuthCells + a;
}

FreeSpaceImage::Seen FreeSpaceImage::classify(const Eigen::Vector3f& q) const {
  const Eigen::Vector3f d = q - scanner_;
  const float range = d.norm();
  if (range <= margin_) return Seen::kUnknown;
  const float nearest = nearest_[cell(d / range)];
  if (!std::isfinite(nearest)) return Seen::kUnknown;
  if (range < nearest - margin_) return Seen::kEmpty;
  return range <= nearest + margin_ ? Seen::kSurface : Seen::kOccluded;
}

double FreeSpaceImage::median_range_m(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& scanner_m) {
  if (points.empty()) return 0.0;
  std::vector<float> ranges(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) ranges[i] = (points[i] - scanner_m).norm();
  std::nth_element(ranges.begin(), ranges.begin() + ranges.size() / 2, ranges.end());
  return ranges[ranges.size() / 2];
}

}  // namespace k4reg
