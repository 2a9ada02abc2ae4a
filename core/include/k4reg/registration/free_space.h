// Free-space evidence from a scan: the scanner saw along each direction up to its first return, so a
// surface placed nearer than that is contradicted by the scan. A symmetric room rotated by 180 degrees
// fits walls, floor and ceiling as well as the truth does — often better — but puts the furniture of one
// scan where the other scanner looked through empty space. Counting these violations is what separates
// the two (paper's named weakness: symmetric rooms). An object scanner's single view carries the same
// evidence: a back view turned onto the front of a near-symmetric statuette puts its tail where the front
// camera saw through to the background.
// Cost: O(n) to build a range image (cells sized to the scan's density); O(1) per query.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

namespace k4reg {

// Where a scan was seen from: a terrestrial scanner's position, or, for a range camera's single view of an
// object (single_view.h), only the direction toward the camera: from its distance its rays are nearly
// parallel across the object, and a scan moved by an unknown motion keeps no position anyway.
struct Viewpoint {
  bool parallel = false;
  Eigen::Vector3f position_m = Eigen::Vector3f::Zero();        // the scanner (not parallel)
  Eigen::Vector3f toward_scanner = Eigen::Vector3f::UnitZ();   // unit (parallel)

  static Viewpoint at(const Eigen::Vector3f& position_m) { return {false, position_m, Eigen::Vector3f::UnitZ()}; }
  static Viewpoint along(const Eigen::Vector3f& toward_scanner) {
    return {true, Eigen::Vector3f::Zero(), toward_scanner.normalized()};
  }
  // From the scanner to q: the ray a surface at q is seen along (unit length for a parallel view).
  Eigen::Vector3f ray_to(const Eigen::Vector3f& q) const {
    return parallel ? Eigen::Vector3f(-toward_scanner) : Eigen::Vector3f(q - position_m);
  }
  Viewpoint moved(const Eigen::Affine3f& motion) const {
    return parallel ? along(motion.linear() * toward_scanner) : at(motion * position_m);
  }
};

class FreeSpaceImage {
 public:
  // points: the scan, seen from `viewpoint`. margin_m: how far in front of the first return a point must
  // lie to count as contradicted (noise and voxelisation). A terrestrial scanner's image is spherical, with
  // cells from the point count; a parallel view's is a plane across its rays with cells of parallel_cell_m
  // (a few returns each: twice the sampling spacing or so).
  FreeSpaceImage(const std::vector<Eigen::Vector3f>& points, const Viewpoint& viewpoint, double margin_m,
                 double parallel_cell_m = 0.0);

  enum class Seen {
    kUnknown,   // no return in that direction (a window, beyond its reach, outside its field of view) or too
                // near the scanner
    kEmpty,     // q lies in space the scanner saw to be empty: a contradiction
    kOpen,      // no return around that direction at all, where the scanner looked (within the band of
                // elevations it returned from), q nearer than the range it reaches elsewhere: open sky over
                // a plaza, the background beside an object. A contradiction too, unless the surface at q faces
                // the scanner obliquely or is dark: such surfaces return nothing from afar, so the caller
                // weighs the incidence.
    kSurface,   // q lies at the first return, within the margin
    kOccluded,  // q lies behind the first return
  };
  Seen classify(const Eigen::Vector3f& q) const;
  const Viewpoint& viewpoint() const { return viewpoint_; }
  std::size_t bytes() const;  // heap bytes held

 private:
  struct Located {
    int cell = -1;  // -1: outside the image
    float range = 0;
  };
  Located locate(const Eigen::Vector3f& q) const;
  std::size_t index(int row, int column) const { return static_cast<std::size_t>(row) * columns_ + column; }
  // The column `column + offset`, wrapped around where azimuth wraps; -1 off a parallel image's edge.
  int column_at(int column, int offset) const;
  void mark_open(const std::vector<float>& own, const std::vector<std::size_t>& per_row, std::size_t returns,
                 std::vector<float>& sampled_ranges);
  Viewpoint viewpoint_;
  float margin_;
  int rows_ = 0, columns_ = 0;  // spherical: elevation x azimuth, from the point count: a few returns per cell
  // Parallel: the image plane's axes, its cell, the corner cell's offsets, and the range origin (the plane
  // through the nearest return: ranges grow away from the camera).
  Eigen::Vector3f across_ = Eigen::Vector3f::UnitX(), up_ = Eigen::Vector3f::UnitY();
  float cell_m_ = 0, first_across_ = 0, first_up_ = 0, front_ = 0;
  std::vector<float> nearest_;  // nearest return per cell; +inf where none
  std::vector<bool> open_;      // no return in a wide neighbourhood, within the band of rows seen
  float reach_m_ = 0;           // a range the scanner returns from (99th percentile of its ranges)
};

}  // namespace k4reg
