#include "k4reg/geometry/point_cloud.h"

#include <cmath>
#include <string>

#include "k4reg/util/error.h"

namespace k4reg {
namespace {

// Beyond any position on Earth in any unit down to millimetres; keeps the bounding-box centre and the float
// offsets from it finite.
constexpr double kMaxAbsCoordinate = 1e12;

}  // namespace

PointCloud make_local_cloud(const std::vector<Eigen::Vector3d>& points_world, std::vector<float> intensity,
                            const char* what) {
  PointCloud cloud;
  if (points_world.empty()) return cloud;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (std::size_t i = 0; i < points_world.size(); ++i) {
    const Eigen::Vector3d& p = points_world[i];
    if (!p.allFinite())
      fail(ErrorCode::kInvalidArgument, std::string(what) + ": point " + std::to_string(i) + " has a NaN/Inf coordinate");
    if (p.cwiseAbs().maxCoeff() > kMaxAbsCoordinate)
      fail(ErrorCode::kInvalidArgument, std::string(what) + ": point " + std::to_string(i) +
                                            " has a coordinate beyond +-1e12, not a position in any unit");
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  // A whole-metre origin keeps the offsets exact to print and compare; floats then hold the extent only.
  cloud.origin_m = (0.5 * (lo + hi)).array().round();
  if (cloud.origin_m.cwiseAbs().maxCoeff() < 1e4) cloud.origin_m.setZero();  // near the origin: keep the file's frame
  cloud.points.resize(points_world.size());
  for (std::size_t i = 0; i < points_world.size(); ++i) cloud.points[i] = (points_world[i] - cloud.origin_m).cast<float>();
  if (intensity.size() != points_world.size()) return cloud;
  // A NaN would reach the intensity signal's log and the medians' nth_element (undefined with NaN).
  for (std::size_t i = 0; i < intensity.size(); ++i)
    if (!std::isfinite(intensity[i]))
      fail(ErrorCode::kInvalidArgument, std::string(what) + ": point " + std::to_string(i) + " has a NaN/Inf intensity");
  cloud.intensity = std::move(intensity);
  return cloud;
}

}  // namespace k4reg
