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
    kUnknown,   // no return in that direction (sky, windows, beyond range) or too near the scanner
    kEmpty,     // q lies in space the scanner saw to be empty: a contradiction
    kSurface,   // q lies at the first return, within the margin
    kOccluded,  // q lies behind the first return
  };
  Seen classify(const Eigen::Vector3f& q) const;

  // Median distance of the points from the scanner: small values mean the origin is not a scanner
  // position (e.g. object scans whose frame origin is inside the object).
  static double median_range_m(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& scanner_m);

 private:
  int cell(const Eigen::Vector3f& direction) const;
  Eigen::Vector3f scanner_;
  float margin_;
  int elevation_cells_, azimuth_cells_;  // from the point count: a few returns per cell
  std::vector<float> nearest_;  // nearest return per (azimuth, elevation) cell; +inf where none
};

}  // namespace k4reg
