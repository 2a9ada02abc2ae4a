#include "k4reg/registration/metrics.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace k4reg {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

// Roll-pitch-yaw (x-y-z fixed axes, R = Rz * Ry * Rx) of a rotation, each in (-180, 180].
Eigen::Vector3d euler_xyz(const Eigen::Matrix3d& r) {
  const double pitch = std::asin(std::clamp(-r(2, 0), -1.0, 1.0));
  const double roll = std::atan2(r(2, 1), r(2, 2));
  const double yaw = std::atan2(r(1, 0), r(0, 0));
  return {roll, pitch, yaw};
}

}  // namespace

double mean_angular_error_deg(const Eigen::Matrix4d& estimate, const Eigen::Matrix4d& truth) {
  const Eigen::Matrix3d delta = truth.topLeftCorner<3, 3>().transpose() * estimate.topLeftCorner<3, 3>();
  return euler_xyz(delta).cwiseAbs().mean() * kRadToDeg;
}

double mean_translation_error_m(const Eigen::Matrix4d& estimate, const Eigen::Matrix4d& truth) {
  return (estimate.topRightCorner<3, 1>() - truth.topRightCorner<3, 1>()).cwiseAbs().mean();
}

double rotation_angle_deg(const Eigen::Matrix3d& rotation) {
  return Eigen::AngleAxisd(rotation).angle() * kRadToDeg;
}

double true_correspondence_rmse_m(const std::vector<Eigen::Vector3f>& source_points, const Eigen::Matrix4d& estimate,
                                  const Eigen::Matrix4d& truth) {
  if (source_points.empty()) return 0.0;
  // (T_est - T_gt) * p, accumulated in double: exact even for survey-sized translations.
  const Eigen::Matrix4d diff = estimate - truth;
  double sum = 0.0;
  for (const Eigen::Vector3f& p : source_points)
    sum += (diff.topLeftCorner<3, 3>() * p.cast<double>() + diff.topRightCorner<3, 1>()).squaredNorm();
  return std::sqrt(sum / static_cast<double>(source_points.size()));
}

TransformError transform_error(const std::vector<Eigen::Vector3f>& source_points, const Eigen::Matrix4d& estimate,
                               const Eigen::Matrix4d& truth) {
  TransformError e;
  e.mae_deg = mean_angular_error_deg(estimate, truth);
  e.mte_m = mean_translation_error_m(estimate, truth);
  e.rotation_deg =
      rotation_angle_deg(truth.topLeftCorner<3, 3>().transpose() * estimate.topLeftCorner<3, 3>());
  e.translation_m = (estimate.topRightCorner<3, 1>() - truth.topRightCorner<3, 1>()).norm();
  e.rmse_m = true_correspondence_rmse_m(source_points, estimate, truth);
  return e;
}

}  // namespace k4reg
