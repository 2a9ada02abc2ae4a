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
  constexpr std::size_t kRangeSampleEvery = 16;  // the reach is a quantile: a sample of the ranges will do
  std::vector<float> sampled_ranges;
  std::vector<std::size_t> per_row(elevation_cells_, 0);
  sampled_ranges.reserve(points.size() / kRangeSampleEvery + 1);
  std::size_t returns = 0;
  for (const Eigen::Vector3f& p : points) {
    const Eigen::Vector3f d = p - scanner_;
    const float range = d.norm();
    if (range <= 0) continue;
    const int c = cell(d / range);
    float& nearest = nearest_[c];
    nearest = std::min(nearest, range);
    if (returns++ % kRangeSampleEvery == 0) sampled_ranges.push_back(range);
    ++per_row[c / azimuth_cells_];
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
  mark_open(own, per_row, returns, sampled_ranges);
}

// A scanner that returns from 70 m in most directions and from nothing in a wide patch of directions saw
// no surface there within its reach: the sky over a plaza. A pose that puts trees or a facade into that
// sky is contradicted as surely as one that puts them into a room's empty air. Only where the scanner
// looked: within the band of elevations it returned from (a profiler or a Velodyne sees a band only), and
// only where the whole neighbourhood is empty (a dark patch or a window leaves a hole of a cell or two).
void FreeSpaceImage::mark_open(const std::vector<float>& own, const std::vector<std::size_t>& per_row,
                               std::size_t returns, std::vector<float>& sampled_ranges) {
  constexpr double kBandTail = 0.001;     // share of returns ignored at each end of the elevation band
  constexpr double kReachQuantile = 0.99;
  constexpr int kOpenRadiusCells = 3;     // 7 x 7 cells: 3.5 degrees for 0.7 M points
  open_.assign(own.size(), false);
  if (returns < 1000 || sampled_ranges.empty()) return;  // too few returns to tell a hole from sparse sampling
  const std::size_t tail = static_cast<std::size_t>(kBandTail * returns);
  int first_row = 0, last_row = elevation_cells_ - 1;
  for (std::size_t below = 0; first_row < elevation_cells_ && below + per_row[first_row] <= tail; ++first_row)
    below += per_row[first_row];
  for (std::size_t above = 0; last_row >= 0 && above + per_row[last_row] <= tail; --last_row) above += per_row[last_row];
  const auto nth = sampled_ranges.begin() + static_cast<std::ptrdiff_t>(kReachQuantile * (sampled_ranges.size() - 1));
  std::nth_element(sampled_ranges.begin(), nth, sampled_ranges.end());
  reach_m_ = *nth;
  for (int e = first_row + kOpenRadiusCells; e <= last_row - kOpenRadiusCells; ++e)
    for (int a = 0; a < azimuth_cells_; ++a) {
      // Only cells without a return around them are ever asked (classify).
      if (std::isfinite(nearest_[static_cast<std::size_t>(e) * azimuth_cells_ + a])) continue;
      bool empty = true;
      for (int de = -kOpenRadiusCells; de <= kOpenRadiusCells && empty; ++de)
        for (int da = -kOpenRadiusCells; da <= kOpenRadiusCells && empty; ++da) {
          const int aa = (a + da + azimuth_cells_) % azimuth_cells_;
          empty = !std::isfinite(own[static_cast<std::size_t>(e + de) * azimuth_cells_ + aa]);
        }
      open_[static_cast<std::size_t>(e) * azimuth_cells_ + a] = empty;
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
  const int c = cell(d / range);
  const float nearest = nearest_[c];
  if (!std::isfinite(nearest)) return open_[c] && range < reach_m_ ? Seen::kOpen : Seen::kUnknown;
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
