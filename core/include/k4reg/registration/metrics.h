// The paper's evaluation measures (Sec. 3), shared by tests, benchmarks and the CLI.
// All transforms map source -> target (p_target = T * p_source).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace k4reg {

struct TransformError {
  double mae_deg = 0.0;          // mean |Euler angle| (roll, pitch, yaw) of R_gt^T * R_est
  double mte_m = 0.0;            // mean |component| of t_est - t_gt
  double rotation_deg = 0.0;     // geodesic rotation angle of R_gt^T * R_est (shows 180 deg flips)
  double translation_m = 0.0;    // |t_est - t_gt|
  double rmse_m = 0.0;           // RMS distance between T_est*p and T_gt*p (true correspondences)
};

// Success thresholds of the paper: coarse RMSE below 0.5 m indoors, 1 m outdoors.
constexpr double kIndoorSuccessRmse_m = 0.5;
constexpr double kOutdoorSuccessRmse_m = 1.0;

double mean_angular_error_deg(const Eigen::Matrix4d& estimate, const Eigen::Matrix4d& truth);
double mean_translation_error_m(const Eigen::Matrix4d& estimate, const Eigen::Matrix4d& truth);
double rotation_angle_deg(const Eigen::Matrix3d& rotation);
// RMS of |T_est * p - T_gt * p| over the given points (source frame). 0 for no points.
double true_correspondence_rmse_m(const std::vector<Eigen::Vector3f>& source_points, const Eigen::Matrix4d& estimate,
                                  const Eigen::Matrix4d& truth);

TransformError transform_error(const std::vector<Eigen::Vector3f>& source_points, const Eigen::Matrix4d& estimate,
                               const Eigen::Matrix4d& truth);

inline bool registration_succeeded(const TransformError& e, double rmse_threshold_m) {
  return e.rmse_m < rmse_threshold_m;
}

}  // namespace k4reg
