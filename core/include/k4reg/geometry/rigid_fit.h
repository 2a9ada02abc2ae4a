// Closed-form least-squares rigid transform between corresponding point sets (Kabsch / Umeyama,
// no scale). Cost: O(n).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace k4reg {

// T minimising sum |T * from[i] - to[i]|^2; from and to are 3 x n with n >= 3.
inline Eigen::Matrix4d fit_rigid(const Eigen::Matrix3Xd& from, const Eigen::Matrix3Xd& to) {
  return Eigen::umeyama(from, to, false);
}

// RMS residual of T applied to corresponding points.
inline double fit_rms(const Eigen::Matrix4d& t, const Eigen::Matrix3Xd& from, const Eigen::Matrix3Xd& to) {
  const Eigen::Matrix3Xd moved = (t.topLeftCorner<3, 3>() * from).colwise() + t.topRightCorner<3, 1>();
  return std::sqrt((moved - to).colwise().squaredNorm().mean());
}

// Float transform for moving many float points quickly.
inline Eigen::Affine3f to_affine3f(const Eigen::Matrix4d& t) {
  Eigen::Affine3f a;
  a.matrix() = t.cast<float>();
  return a;
}

}  // namespace k4reg
