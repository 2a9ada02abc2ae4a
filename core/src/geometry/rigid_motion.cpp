#include "k4reg/geometry/rigid_motion.h"

#include <Eigen/Geometry>
#include <cmath>

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

double shift_at_m(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b, const Eigen::Vector3d& at_m) {
  const Eigen::Matrix4d d = a - b;
  return (d.topLeftCorner<3, 3>() * at_m + d.topRightCorner<3, 1>()).norm();
}

double displacement_m(const Eigen::Matrix4d& t, const ScanExtent& scan) {
  const double angle = Eigen::AngleAxisd(Eigen::Matrix3d(t.topLeftCorner<3, 3>())).angle();
  const double shift = shift_at_m(t, Eigen::Matrix4d::Identity(), scan.centre_m);
  const double turn = scan.radius_m * angle;
  return std::sqrt(shift * shift + turn * turn);
}

bool distinct_transforms(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b, const Eigen::Vector3d& at_m,
                         double min_angle_deg, double min_shift_m) {
  const Eigen::Matrix3d turn = a.topLeftCorner<3, 3>().transpose() * b.topLeftCorner<3, 3>();
  const double angle_deg = Eigen::AngleAxisd(turn).angle() * 180.0 / M_PI;
  return angle_deg >= min_angle_deg || shift_at_m(a, b, at_m) >= min_shift_m;
}

Eigen::Vector3d centroid(const std::vector<Eigen::Vector3f>& points) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& p : points) sum += p.cast<double>();
  return points.empty() ? sum : Eigen::Vector3d(sum / static_cast<double>(points.size()));
}

Eigen::Matrix4d rigid_inverse(const Eigen::Matrix4d& t) {
  Eigen::Matrix4d inv = Eigen::Matrix4d::Identity();
  inv.topLeftCorner<3, 3>() = t.topLeftCorner<3, 3>().transpose();
  inv.topRightCorner<3, 1>() = -inv.topLeftCorner<3, 3>() * t.topRightCorner<3, 1>();
  return inv;
}

}  // namespace k4reg
