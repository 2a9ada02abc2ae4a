// Comparing poses of a scan where the scan is: two poses that differ by a small turn about the scan's centre are
// the same pose wherever the file puts its origin, and a turn or a shift beyond the bars is a different one.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "k4reg/geometry/rigid_motion.h"

namespace k4reg {
namespace {

// A turn by angle_deg about the vertical through centre.
Eigen::Matrix4d turn_about(const Eigen::Vector3d& centre, double angle_deg) {
  Eigen::Matrix4d t = Eigen::Matrix4d::Identity();
  t.topLeftCorner<3, 3>() = Eigen::AngleAxisd(angle_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  t.topRightCorner<3, 1>() = centre - t.topLeftCorner<3, 3>() * centre;
  return t;
}

TEST(RigidMotion, PosesAreComparedAtTheScanNotAtTheOrigin) {
  for (const Eigen::Vector3d& centre : {Eigen::Vector3d(0.1, 0.0, 0.0), Eigen::Vector3d(29.0, 29.0, 0.0)}) {
    const Eigen::Matrix4d a = Eigen::Matrix4d::Identity(), b = turn_about(centre, 1.0);
    // 1 degree about the scan's centre moves its centre nowhere: within a 2-degree, 1 cm bar it is the same pose,
    // though its raw translation is 0.7 m where the scan lies 41 m from the origin.
    EXPECT_FALSE(distinct_transforms(a, b, centre, 2.0, 0.01)) << centre.transpose();
    EXPECT_NEAR(shift_at_m(a, b, centre), 0.0, 1e-9);
    EXPECT_TRUE(distinct_transforms(a, b, centre, 0.5, 0.01));  // beyond the angle bar
    Eigen::Matrix4d shifted = a;
    shifted(0, 3) = 0.02;
    EXPECT_TRUE(distinct_transforms(a, shifted, centre, 2.0, 0.01));  // beyond the shift bar
    EXPECT_NEAR(shift_at_m(a, shifted, centre), 0.02, 1e-12);
  }
}

TEST(RigidMotion, DisplacementIsMeasuredWhereTheScanIs) {
  // A scan 0.2 m across: a 0.1-degree turn about its centre moves its points by 0.35 mm wherever it lies.
  for (const Eigen::Vector3d& centre : {Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(29.0, -29.0, 12.0)}) {
    const ScanExtent scan{centre, 0.2};
    EXPECT_NEAR(displacement_m(turn_about(centre, 0.1), scan), 0.2 * 0.1 * M_PI / 180.0, 1e-9) << centre.transpose();
    Eigen::Matrix4d shifted = Eigen::Matrix4d::Identity();
    shifted.topRightCorner<3, 1>() = Eigen::Vector3d(0.003, 0.004, 0.0);
    EXPECT_NEAR(displacement_m(shifted, scan), 0.005, 1e-12);
  }
  // The same turn about the file's origin moves a scan 43 m away by 7.5 cm.
  EXPECT_NEAR(displacement_m(turn_about(Eigen::Vector3d::Zero(), 0.1), {Eigen::Vector3d(29.0, -29.0, 12.0), 0.2}),
              std::hypot(std::hypot(29.0, 29.0) * 0.1 * M_PI / 180.0, 0.2 * 0.1 * M_PI / 180.0), 1e-6);
}

TEST(RigidMotion, CentroidIsTheMeanInDouble) {
  EXPECT_TRUE(centroid({}).isZero());
  const std::vector<Eigen::Vector3f> points{{29.0f, 1.0f, 0.0f}, {31.0f, 3.0f, 2.0f}};
  EXPECT_TRUE(centroid(points).isApprox(Eigen::Vector3d(30.0, 2.0, 1.0)));
}

}  // namespace
}  // namespace k4reg
