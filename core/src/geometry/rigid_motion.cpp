#include "k4reg/geometry/rigid_motion.h"

#include <Eigen/Geometry>

namespace k4reg {

Eigen::Matrix3d rotation_exp(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  if (angle < 1e-12) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

Eigen::Vector3d rotation_log(const Eigen::Matrix3d& r) {
  const Eigen::AngleAxisd aa(r);
  return aa.angle() * aa.axis();
}

double displacement_m(const Eigen::Matrix4d& t, double lever_arm_m) {
  const double angle = Eigen::AngleAxisd(Eigen::Matrix3d(t.topLeftCorner<3, 3>())).angle();
  const double shift = t.topRightCorner<3, 1>().norm();
  return std::sqrt(shift * shift + lever_arm_m * angle * lever_arm_m * angle);
}

Eigen::Matrix4d rigid_inverse(const Eigen::Matrix4d& t) {
  Eigen::Matrix4d inv = Eigen::Matrix4d::Identity();
  inv.topLeftCorner<3, 3>() = t.topLeftCorner<3, 3>().transpose();
  inv.topRightCorner<3, 1>() = -inv.topLeftCorner<3, 3>() * t.topRightCorner<3, 1>();
  return inv;
}

}  // namespace k4reg
