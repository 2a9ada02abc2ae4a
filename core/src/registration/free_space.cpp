#include "k4reg/registration/free_space.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace k4reg {
namespace {

// Cells of about four returns each on average (half a degree for 0.7 M points over the sphere, about
// 9 cm at 10 m): fine enough to see past furniture, coarse enough that the scan fills them.
int elevation_cells_for(std::size_t points) {
  constexpr double kReturnsPerCell = 4.0;
  const double cell_rad = std::sqrt(4.0 * M_PI * kReturnsPerCell / std::max<std::size_t>(points, 1));
  return std::clamp(static_cast<int>(M_PI / cell_rad), 45, 1800);  // 4 to 0.1 degrees
}

}  // namespace

FreeSpaceImage::FreeSpaceImage(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& scanner_m,
                               double margin_m)
    : scanner_(scanner_m),
      margin_(static_cast<float>(margin_m)),
      elevation_cells_(elevation_cells_for(points.size())),
      azimuth_cells_(2 * elevation_cells_),
      nearest_(static_cast<std::size_t>(azimuth_cells_) * elevation_cells_, std::numeric_limits<float>::infinity()) {
  for (const Eigen::Vector3f& p : points) {
    const Eigen::Vector3f d = p - scanner_;
    const float range = d.norm();
    if (range <= 0) continue;
    float& nearest = nearest_[cell(d / range)];
    nearest = std::min(nearest, range);
  }
  // Each cell takes the nearest return of its 3 x 3 neighbourhood. A cell's few returns may all lie at
  // its far side: on a surface seen at grazing incidence the range changes by metres across one cell,
  // and a point at the near side would count as seen through. Only what is nearer than every return
  // around it is contradicted.
  std::vector<float> own = nearest_;
  for (int e = 0; e < elevation_cells_; ++e)
    for (int a = 0; a < azimuth_cells_; ++a) {
      float& nearest = nearest_[static_cast<std::size_t>(e) * azimuth_cells_ + a];
      for (int de = -1; de <= 1; ++de) {
        const int ee = e + de;
        if (ee < 0 || ee >= elevation_cells_) continue;
        for (int da = -1; da <= 1; ++da) {
          const int aa = (a + da + azimuth_cells_) % azimuth_cells_;  // azimuth wraps around
          nearest = std::min(nearest, own[static_cast<std::size_t>(ee) * azimuth_cells_ + aa]);
        }
      }
    }
}

int FreeSpaceImage::cell(const Eigen::Vector3f& u) const {
  const float azimuth = std::atan2(u.y(), u.x()) + static_cast<float>(M_PI);      // [0, 2 pi]
  const float elevation = std::acos(std::clamp(u.z(), -1.0f, 1.0f));               // [0, pi]
  const int a = std::min(azimuth_cells_ - 1, static_cast<int>(azimuth * (azimuth_cells_ / (2 * M_PI))));
  const int e = std::min(elevation_cells_ - 1, static_cast<int>(elevation * (elevation_cells_ / M_PI)));
  return e * azimuth_cells_ + a;
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
