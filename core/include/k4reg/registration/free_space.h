// Free-space evidence from a terrestrial scan: the scanner saw along each direction up to its first
// return, so a surface placed nearer than that is contradicted by the scan. A symmetric room rotated
// by 180 degrees fits walls, floor and ceiling as well as the truth does — often better — but puts
// the furniture of one scan where the other scanner looked through empty space. Counting these
// violations is what separates the two (paper's named weakness: symmetric rooms).
// Cost: O(n) to build a spherical range image (cells sized to the scan's density); O(1) per query.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace k4reg {

class FreeSpaceImage {
 public:
  // points: the scan in a frame where the scanner sits at scanner_m. margin_m: how far in front of the
  // first return a point must lie to count as contradicted (noise and voxelisation).
  FreeSpaceImage(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& scanner_m, double margin_m);

  enum class Seen {
    kUnknown,   // no return in that direction (a window, beyond its reach, outside its field of view) or too
                // near the scanner
    kEmpty,     // q lies in space the scanner saw to be empty: a contradiction
    kOpen,      // no return around that direction at all, where the scanner looked (within the band of
                // elevations it returned from), q nearer than the range it reaches elsewhere: open sky over
                // a plaza. A contradiction too, unless the surface at q faces the scanner obliquely or is
                // dark: such surfaces return nothing from afar, so the caller weighs the incidence.
    kSurface,   // q lies at the first return, within the margin
    kOccluded,  // q lies behind the first return
  };
  Seen classify(const Eigen::Vector3f& q) const;

  // Median distance of the points from the scanner: small values mean the origin is not a scanner
  // position (e.g. object scans whose frame origin is inside the object).
  static double median_range_m(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& scanner_m);

 private:
  int cell(const Eigen::Vector3f& direction) const;
  void mark_open(const std::vector<float>& own, const std::vector<std::size_t>& per_row, std::size_t returns,
                 std::vector<float>& sampled_ranges);
  Eigen::Vector3f scanner_;
  float margin_;
  int elevation_cells_, azimuth_cells_;  // from the point count: a few returns per cell
  std::vector<float> nearest_;  // nearest return per (azimuth, elevation) cell; +inf where none
  std::vector<bool> open_;      // no return in a wide neighbourhood, within the band of elevations seen
  float reach_m_ = 0;           // a range the scanner returns from (99th percentile of its ranges)
};

}  // namespace k4reg
