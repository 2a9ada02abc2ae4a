#include "k4reg/registration/metrics.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

namespace k4reg {
namespace {

Eigen::Matrix4d pose(double roll_deg, double pitch_deg, double yaw_deg, Eigen::Vector3d t) {
  const double k = M_PI / 180;
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = (Eigen::AngleAxisd(yaw_deg * k, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(pitch_deg * k, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(roll_deg * k, Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  m.topRightCorner<3, 1>() = t;
  return m;
}

TEST(Metrics, IdenticalTransformsHaveNoError) {
  const Eigen::Matrix4d t = pose(10, 20, 30, {1, 2, 3});
  const std::vector<Eigen::Vector3f> points{{1, 0, 0}, {0, 5, 0}, {0, 0, -2}};
  const TransformError e = transform_error(points, t, t);
  EXPECT_NEAR(e.mae_deg, 0, 1e-9);
  EXPECT_NEAR(e.mte_m, 0, 1e-12);
  EXPECT_NEAR(e.rmse_m, 0, 1e-12);
  EXPECT_TRUE(registration_succeeded(e, kIndoorSuccessRmse_m));
}

TEST(Metrics, EulerAngleAndTranslationErrors) {
  const Eigen::Matrix4d truth = pose(0, 0, 0, {0, 0, 0});
  // Rotation errors of 3, 6 and 9 degrees about x, y, z: MAE = 6 degrees.
  EXPECT_NEAR(mean_angular_error_deg(pose(3, 6, 9, {0, 0, 0}), truth), 6.0, 1e-9);
  // Translation error (0.3, -0.6, 0.9): MTE = mean |component| = 0.6.
  EXPECT_NEAR(mean_translation_error_m(pose(0, 0, 0, {0.3, -0.6, 0.9}), truth), 0.6, 1e-12);
  EXPECT_NEAR(rotation_angle_deg(pose(0, 0, 180, {0, 0, 0}).topLeftCorner<3, 3>()), 180.0, 1e-9);
}

TEST(Metrics, RmseUsesTrueCorrespondences) {
  // A 1 m shift moves every point by exactly 1 m, whatever the nearest neighbours are.
  const std::vector<Eigen::Vector3f> points{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {5, 5, 5}};
  const Eigen::Matrix4d truth = pose(0, 0, 0, {0, 0, 0});
  EXPECT_NEAR(true_correspondence_rmse_m(points, pose(0, 0, 0, {1, 0, 0}), truth), 1.0, 1e-12);
  // A 180 degree turn about z: |R p - p| = 2 * horizontal radius.
  const double expected = std::sqrt((0 + 4 + 4 + 4 * 50) / 4.0);
  EXPECT_NEAR(true_correspondence_rmse_m(points, pose(0, 0, 180, {0, 0, 0}), truth), expected, 1e-5);
  const TransformError flip = transform_error(points, pose(0, 0, 180, {0, 0, 0}), truth);
  EXPECT_FALSE(registration_succeeded(flip, kIndoorSuccessRmse_m));
  EXPECT_EQ(true_correspondence_rmse_m({}, truth, truth), 0.0);
}

TEST(Metrics, SurveySizedTranslationsStayExact) {
  const Eigen::Matrix4d truth = pose(1, 2, 3, {500000.0, 5240000.0, 400.0});
  Eigen::Matrix4d estimate = truth;
  estimate(0, 3) += 0.001;
  const std::vector<Eigen::Vector3f> points{{10, 20, 1}, {-30, 5, 2}};
  EXPECT_NEAR(true_correspondence_rmse_m(points, estimate, truth), 0.001, 1e-9);
}

}  // namespace
}  // namespace k4reg
