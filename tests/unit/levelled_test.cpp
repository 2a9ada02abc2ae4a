// Levelled scanners (RegistrationParams::levelled): every fit, ICP step, symmetric twin and global refinement is
// a rotation about z and a translation. Scans of the simulated lab re-expressed in levelled frames (the scanner
// at the origin, z up, an arbitrary heading) register to the truth with no tilt at all.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "k4reg/geometry/rigid_fit.h"
#include "k4reg/project/project_registration.h"
#include "k4reg/registration/icp.h"
#include "k4reg/registration/registration.h"
#include "sim/scanner.h"
#include "sim/scene.h"

namespace k4reg {
namespace {

Eigen::Matrix4d yaw_and_shift(double yaw_deg, const Eigen::Vector3d& shift_m) {
  Eigen::Matrix4d t = Eigen::Matrix4d::Identity();
  t.topLeftCorner<3, 3>() = Eigen::AngleAxisd(yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  t.topRightCorner<3, 1>() = shift_m;
  return t;
}

// No rotation about x or y, to the last bit a rotation about z can leave.
::testing::AssertionResult is_levelled(const Eigen::Matrix4d& t) {
  const double tilt = std::max({std::abs(t(0, 2)), std::abs(t(1, 2)), std::abs(t(2, 0)), std::abs(t(2, 1)),
                                std::abs(t(2, 2) - 1.0)});
  if (tilt < 1e-12) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "tilted by " << tilt << ":\n" << t;
}

double rotation_error_deg(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b) {
  return Eigen::AngleAxisd(a.topLeftCorner<3, 3>().transpose() * b.topLeftCorner<3, 3>()).angle() * 180.0 / M_PI;
}

// A lab station as a levelled scanner records it: scanner at the origin, z up, heading `yaw_deg`.
// `scan_to_world` receives the truth (scan frame -> scene frame).
PointCloud levelled_lab_scan(int station, double yaw_deg, Eigen::Matrix4d& scan_to_world) {
  static const sim::Scene lab = sim::make_scene("lab");
  sim::ScanParams params;
  params.points = 60000;
  const sim::SimulatedScan scan = sim::simulate_scan(lab, station, params);
  const Eigen::Matrix4d world_to_scan = yaw_and_shift(yaw_deg, Eigen::Vector3d::Zero()) *
                                        yaw_and_shift(0.0, -scan.station_m);
  scan_to_world = world_to_scan.inverse();
  const Eigen::Matrix4d to_levelled = world_to_scan * scan.scan_to_scene;
  std::vector<Eigen::Vector3d> points;
  for (const Eigen::Vector3f& p : scan.cloud.points)
    points.push_back(to_levelled.topLeftCorner<3, 3>() * (scan.cloud.origin_m + p.cast<double>()) +
                     to_levelled.topRightCorner<3, 1>());
  return make_local_cloud(points, scan.cloud.intensity);
}

TEST(Levelled, FitAboutZRecoversHeadingAndShiftAndNeverTilts) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coordinate(-5.0, 5.0);
  Eigen::Matrix3Xd from(3, 6);
  for (Eigen::Index i = 0; i < from.cols(); ++i) {
    const double x = coordinate(rng), y = coordinate(rng), z = coordinate(rng);
    from.col(i) = Eigen::Vector3d(x, y, z);
  }
  const Eigen::Matrix4d truth = yaw_and_shift(123.0, {1.0, -2.0, 0.5});
  const Eigen::Matrix3Xd to = (truth.topLeftCorner<3, 3>() * from).colwise() + truth.topRightCorner<3, 1>();
  const Eigen::Matrix4d fitted = fit_rigid_about_z(from, to);
  EXPECT_TRUE(fitted.isApprox(truth, 1e-12)) << fitted;
  EXPECT_LT(fit_rms(fitted, from, to), 1e-12);
  // Points that only a tilt would match: the fit stays levelled, and its residual shows the mismatch.
  Eigen::Matrix4d tilted = truth;
  tilted.topLeftCorner<3, 3>() = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()).toRotationMatrix() *
                                 truth.topLeftCorner<3, 3>();
  const Eigen::Matrix3Xd tilted_to = (tilted.topLeftCorner<3, 3>() * from).colwise() + tilted.topRightCorner<3, 1>();
  const Eigen::Matrix4d levelled_fit = fit_rigid_about_z(from, tilted_to);
  EXPECT_TRUE(is_levelled(levelled_fit));
  EXPECT_GT(fit_rms(levelled_fit, from, tilted_to), 0.3);
}

TEST(Levelled, IcpTurnsOnlyAboutZ) {
  Eigen::Matrix4d truth_unused;
  const PointCloud cloud = levelled_lab_scan(0, 0.0, truth_unused);
  const Eigen::Matrix4d truth = yaw_and_shift(2.0, {0.08, -0.05, 0.03});
  std::vector<Eigen::Vector3f> moved;
  for (const Eigen::Vector3f& p : cloud.points) moved.push_back((truth.cast<float>() * p.homogeneous()).head<3>());
  IcpParams params;
  params.voxel_m = 0.05;
  params.levelled = true;
  const IcpPyramid source = make_icp_pyramid(cloud.points, params, PyramidRole::kSource);
  const IcpPyramid target = make_icp_pyramid(moved, params, PyramidRole::kTarget);
  const IcpResult result = refine_icp(source, target, Eigen::Matrix4d::Identity(), params);
  EXPECT_TRUE(is_levelled(result.transform));
  EXPECT_LT(rotation_error_deg(result.transform, truth), 0.05);
  EXPECT_LT((result.transform.topRightCorner<3, 1>() - truth.topRightCorner<3, 1>()).norm(), 0.01);
}

TEST(Levelled, PairRegistersWithoutTiltAtAnyHeading) {
  Eigen::Matrix4d source_to_world, target_to_world;
  const PointCloud source = levelled_lab_scan(0, 140.0, source_to_world);
  const PointCloud target = levelled_lab_scan(2, -35.0, target_to_world);
  RegistrationParams params;
  params.min_scale_m = 0.1;
  params.overlap = 0.8;
  params.seed = 1;
  params.levelled = true;
  const RegistrationResult result = register_clouds(source, target, params);
  const Eigen::Matrix4d truth = target_to_world.inverse() * source_to_world;
  EXPECT_TRUE(is_levelled(result.transform));
  for (const Hypothesis& h : result.hypotheses) EXPECT_TRUE(is_levelled(h.transform));
  EXPECT_LT(rotation_error_deg(result.transform, truth), 0.5);
  EXPECT_LT((result.transform.topRightCorner<3, 1>() - truth.topRightCorner<3, 1>()).norm(), 0.05);
  // The lab's one real symmetry is a half-turn about the vertical, which a levelled search keeps (the margin
  // flags it, as without levelling); the tilted hypotheses are gone.
  params.levelled = false;
  const RegistrationResult free = register_clouds(source, target, params);
  EXPECT_LE(result.hypotheses.size(), free.hypotheses.size());
  EXPECT_EQ(result.ambiguous, free.ambiguous);
}

TEST(Levelled, ProjectPosesStayLevelled) {
  std::vector<PointCloud> scans;
  std::vector<Eigen::Matrix4d> truth(3);
  const double headings[] = {10.0, 100.0, -150.0};
  for (int s = 0; s < 3; ++s) scans.push_back(levelled_lab_scan(s, headings[s], truth[s]));
  ProjectParams params;
  params.pairwise.min_scale_m = 0.1;
  params.pairwise.overlap = 0.6;
  params.pairwise.seed = 1;
  params.pairwise.levelled = true;
  const ProjectResult result = register_project(scans, params);
  ASSERT_EQ(result.scans_registered, 3u);
  for (int s = 0; s < 3; ++s) {
    const Eigen::Matrix4d expected = truth[0].inverse() * truth[s];
    EXPECT_TRUE(is_levelled(result.scans[s].pose)) << "scan " << s;
    EXPECT_LT(rotation_error_deg(result.scans[s].pose, expected), 0.5) << "scan " << s;
    EXPECT_LT((result.scans[s].pose.topRightCorner<3, 1>() - expected.topRightCorner<3, 1>()).norm(), 0.05)
        << "scan " << s;
  }
}

}  // namespace
}  // namespace k4reg
