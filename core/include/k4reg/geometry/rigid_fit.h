// Closed-form least-squares rigid transform between corresponding point sets (Kabsch / Umeyama,
// no scale). Cost: O(n).
#pragma once

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace k4reg {

// T minimising sum |T * from[i] - to[i]|^2; from and to are 3 x n with n >= 3.
inline Eigen::Matrix4d fit_rigid(const Eigen::Matrix3Xd& from, const Eigen::Matrix3Xd& to) {
  return Eigen::umeyama(from, to, false);
}

// The same restricted to a rotation about z and a translation (levelled scanners: their z axes are vertical),
// in closed form: the centroids fix the translation, the xy cross-covariance the angle. Cost: O(n).
inline Eigen::Matrix4d fit_rigid_about_z(const Eigen::Matrix3Xd& from, const Eigen::Matrix3Xd& to) {
  const Eigen::Vector3d from_mean = from.rowwise().mean(), to_mean = to.rowwise().mean();
  double cosine_sum = 0.0, sine_sum = 0.0;
  for (Eigen::Index i = 0; i < from.cols(); ++i) {
    const Eigen::Vector3d p = from.col(i) - from_mean, q = to.col(i) - to_mean;
    cosine_sum += p.x() * q.x() + p.y() * q.y();
    sine_sum += p.x() * q.y() - p.y() * q.x();
  }
  Eigen::Matrix4d t = Eigen::Matrix4d::Identity();
  t.topLeftCorner<3, 3>() = Eigen::AngleAxisd(std::atan2(sine_sum, cosine_sum), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  t.topRightCorner<3, 1>() = to_mean - t.topLeftCorner<3, 3>() * from_mean;
  return t;
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
