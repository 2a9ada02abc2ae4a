// The one cloud type of the library: float points in a local frame plus the double-precision
// offset of that frame, so survey coordinates (e.g. 5 240 000 m northing) keep millimetres.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <vector>

namespace k4reg {

struct PointCloud {
  // Point i in the file's frame is origin_m + points[i] (computed in double).
  std::vector<Eigen::Vector3f> points;
  // Either empty (no intensity in the source) or one value per point, in the file's own units.
  std::vector<float> intensity;
  Eigen::Vector3d origin_m = Eigen::Vector3d::Zero();
  // Where the scanner stood, in the file's frame, where the file says it (one E57 scan's pose, one PTX scan's
  // scanner registration); unset otherwise (see scanner_position.h).
  std::optional<Eigen::Vector3d> scanner_m;

  std::size_t size() const { return points.size(); }
  bool empty() const { return points.empty(); }
  bool has_intensity() const { return !intensity.empty() && intensity.size() == points.size(); }
};

// Builds a cloud from double-precision coordinates: picks a local origin (rounded centre of the
// bounding box) and stores float offsets from it. Throws kInvalidArgument on NaN/Inf and on coordinates
// beyond +-1e12 (whose offsets would not fit a float).
PointCloud make_local_cloud(const std::vector<Eigen::Vector3d>& points_world, std::vector<float> intensity,
                            const char* what = "cloud");

}  // namespace k4reg
