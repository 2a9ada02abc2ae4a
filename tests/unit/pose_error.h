// How far a registered pose is from the truth, as the tests measure it.
#pragma once

#include <Eigen/Core>
#include <cmath>

#include "k4reg/geometry/point_cloud.h"

namespace k4reg {

// RMS over the cloud's points of the distance between where `pose` and `truth` put them.
inline double rms_error_m(const PointCloud& cloud, const Eigen::Matrix4d& pose, const Eigen::Matrix4d& truth) {
  double sum = 0.0;
  for (const Eigen::Vector3f& p : cloud.points) {
    Eigen::Vector4d q = Eigen::Vector4d::Ones();
    q.head<3>() = p.cast<double>() + cloud.origin_m;
    sum += (pose * q - truth * q).squaredNorm();
  }
  return std::sqrt(sum / cloud.size());
}

}  // namespace k4reg
