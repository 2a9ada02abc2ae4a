#include "k4reg/registration/free_space.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "k4reg/util/held_bytes.h"

namespace k4reg {
namespace {

// Cells of about four returns each on average (half a degree for 0.7 M points over the sphere, about
// 9 cm at 10 m): fine enough to see past furniture, coarse enough that the scan fills them.
int elevation_cells_for(std::size_t points) {
  constexpr double kReturnsPerCell = 4.0;
  const double cell_rad = std::sqrt(4.0 * M_PI * kReturnsPerCell / std::max<std::size_t>(points, 1));
  return std::clamp(static_cast<int>(M_PI / cell_rad), 45, 1800);  // 4 to 0.1 degrees
}

constexpr int kMaxParallelCells = 2048;  // per side of a parallel image: 4 M cells at most

}  // namespace

FreeSpaceImage::FreeSpaceImage(const std::vector<Eigen::Vector3f>& points, const Viewpoint& viewpoint,
                               double margin_m, double parallel_cell_m)
    : viewpoint_(viewpoint), margin_(static_cast<float>(margin_m)) {
  if (!viewpoint_.parallel) {
    rows_ = elevation_cells_for(points.size());
    columns_ = 2 * rows_;
  } else {
    // The image plane spans the points' extent across the rays; ranges start at the nearest return.
    across_ = viewpoint_.toward_scanner.unitOrthogonal();
    up_ = viewpoint_.toward_scanner.cross(across_);
    constexpr float kInf = std::numeric_limits<float>::infinity();
    Eigen::Vector2f low(kInf, kInf), high(-kInf, -kInf);
    front_ = -kInf;
    for (const Eigen::Vector3f& p : points) {
      const Eigen::Vector2f a(p.dot(across_), p.dot(up_));
      low = low.cwiseMin(a);
      high = high.cwiseMax(a);
      front_ = std::max(front_, p.dot(viewpoint_.toward_scanner));
    }
    if (points.empty()) low = high = Eigen::Vector2f::Zero(), front_ = 0;
    const float extent = (high - low).maxCoeff();
    cell_m_ = std::max({static_cast<float>(parallel_cell_m), extent / kMaxParallelCells, 1e-6f});
    first_across_ = low.x();
    first_up_ = low.y();
    columns_ = static_cast<int>((high.x() - low.x()) / cell_m_) + 1;
    rows_ = static_cast<int>((high.y() - low.y()) / cell_m_) + 1;
  }
  nearest_.assign(static_cast<std::size_t>(rows_) * columns_, std::numeric_limits<float>::infinity());
  constexpr std::size_t kRangeSampleEvery = 16;  // the reach is a quantile: a sample of the ranges will do
  std::vector<float> sampled_ranges;
  std::vector<std::size_t> per_row(rows_, 0);
  sampled_ranges.reserve(points.size() / kRangeSampleEvery + 1);
  std::size_t returns = 0;
  // Located in parallel (an arc tangent or two per point), a block at a time, and folded in the points' order.
  constexpr std::size_t kBlock = 1 << 16;
  std::vector<Located> located(std::min(points.size(), kBlock));
  for (std::size_t first = 0; first < points.size(); first += kBlock) {
    const std::size_t count = std::min(kBlock, points.size() - first);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 4096), [&](const auto& range) {
      for (std::size_t k = range.begin(); k != range.end(); ++k) located[k] = locate(points[first + k]);
    });
    for (std::size_t k = 0; k < count; ++k) {
      const Located& at = located[k];
      if (at.cell < 0) continue;
      float& nearest = nearest_[at.cell];
      nearest = std::min(nearest, at.range);
      if (returns++ % kRangeSampleEvery == 0) sampled_ranges.push_back(at.range);
      ++per_row[at.cell / columns_];
    }
  }
  // Each cell takes the nearest return of its 3 x 3 neighbourhood. A cell's few returns may all lie at
  // its far side: on a surface seen at grazing incidence the range changes by metres across one cell,
  // and a point at the near side would count as seen through. Only what is nearer than every return
  // around it is contradicted.
  std::vector<float> own = nearest_;
  for (int e = 0; e < rows_; ++e)
    for (int a = 0; a < columns_; ++a) {
      float& nearest = nearest_[index(e, a)];
      for (int de = -1; de <= 1; ++de) {
        const int ee = e + de;
        if (ee < 0 || ee >= rows_) continue;
        for (int da = -1; da <= 1; ++da) {
          const int aa = column_at(a, da);
          if (aa >= 0) nearest = std::min(nearest, own[index(ee, aa)]);
        }
      }
    }
  mark_open(own, per_row, returns, sampled_ranges);
}

int FreeSpaceImage::column_at(int column, int offset) const {
  const int c = column + offset;
  if (!viewpoint_.parallel) return (c + columns_) % columns_;  // azimuth wraps around
  return c >= 0 && c < columns_ ? c : -1;
}

// A scanner that returns from 70 m in most directions and from nothing in a wide patch of directions saw
// no surface there within its reach: the sky over a plaza. A pose that puts trees or a facade into that
// sky is contradicted as surely as one that puts them into a room's empty air. Only where the scanner
// looked: within the band of elevations it returned from (a profiler or a Velodyne sees a band only), and
// only where the whole neighbourhood is empty (a dark patch or a window leaves a hole of a cell or two).
// A range camera's view: the background beside the object, within the rows and columns it returned from.
void FreeSpaceImage::mark_open(const std::vector<float>& own, const std::vector<std::size_t>& per_row,
                               std::size_t returns, std::vector<float>& sampled_ranges) {
  constexpr double kBandTail = 0.001;     // share of returns ignored at each end of the elevation band
  constexpr double kReachQuantile = 0.99;
  constexpr int kOpenRadiusCells = 3;     // 7 x 7 cells: 3.5 degrees for 0.7 M points
  open_.assign(own.size(), false);
  if (returns < 1000 || sampled_ranges.empty()) return;  // too few returns to tell a hole from sparse sampling
  const std::size_t tail = static_cast<std::size_t>(kBandTail * returns);
  int first_row = 0, last_row = rows_ - 1;
  for (std::size_t below = 0; first_row < rows_ && below + per_row[first_row] <= tail; ++first_row)
    below += per_row[first_row];
  for (std::size_t above = 0; last_row >= 0 && above + per_row[last_row] <= tail; --last_row) above += per_row[last_row];
  const auto nth = sampled_ranges.begin() + static_cast<std::ptrdiff_t>(kReachQuantile * (sampled_ranges.size() - 1));
  std::nth_element(sampled_ranges.begin(), nth, sampled_ranges.end());
  reach_m_ = *nth;
  for (int e = first_row + kOpenRadiusCells; e <= last_row - kOpenRadiusCells; ++e)
    for (int a = 0; a < columns_; ++a) {
      // Only cells without a return around them are ever asked (classify).
      if (std::isfinite(nearest_[index(e, a)])) continue;
      bool empty = true;
      for (int de = -kOpenRadiusCells; de <= kOpenRadiusCells && empty; ++de)
        for (int da = -kOpenRadiusCells; da <= kOpenRadiusCells && empty; ++da) {
          const int aa = column_at(a, da);
          empty = aa >= 0 && !std::isfinite(own[index(e + de, aa)]);  // off the image's edge: not known
        }
      open_[index(e, a)] = empty;
    }
}

FreeSpaceImage::Located FreeSpaceImage::locate(const Eigen::Vector3f& q) const {
  if (viewpoint_.parallel) {
    const float a = (q.dot(across_) - first_across_) / cell_m_, u = (q.dot(up_) - first_up_) / cell_m_;
    const float range = front_ - q.dot(viewpoint_.toward_scanner);
    if (!(a >= 0 && a < static_cast<float>(columns_) && u >= 0 && u < static_cast<float>(rows_))) return {-1, range};
    return {static_cast<int>(index(std::min(rows_ - 1, static_cast<int>(u)), std::min(columns_ - 1, static_cast<int>(a)))),
            range};
  }
  const Eigen::Vector3f d = q - viewpoint_.position_m;
  const float range = d.norm();
  if (range <= 0) return {-1, range};
  const Eigen::Vector3f u = d / range;
  const float azimuth = std::atan2(u.y(), u.x()) + static_cast<float>(M_PI);      // [0, 2 pi]
  const float elevation = std::acos(std::clamp(u.z(), -1.0f, 1.0f));               // [0, pi]
  const int a = std::min(columns_ - 1, static_cast<int>(azimuth * (columns_ / (2 * M_PI))));
  const int e = std::min(rows_ - 1, static_cast<int>(elevation * (rows_ / M_PI)));
  return {static_cast<int>(index(e, a)), range};
}

std::size_t FreeSpaceImage::bytes() const { return held_bytes(nearest_) + held_bytes(open_); }

FreeSpaceImage::Seen FreeSpaceImage::classify(const Eigen::Vector3f& q) const {
  const Located at = locate(q);
  if (!viewpoint_.parallel && at.range <= margin_) return Seen::kUnknown;
  if (at.cell < 0) return Seen::kUnknown;
  const float nearest = nearest_[at.cell];
  if (!std::isfinite(nearest)) return open_[at.cell] && at.range < reach_m_ ? Seen::kOpen : Seen::kUnknown;
  if (at.range < nearest - margin_) return Seen::kEmpty;
  return at.range <= nearest + margin_ ? Seen::kSurface : Seen::kOccluded;
}

}  // namespace k4reg
