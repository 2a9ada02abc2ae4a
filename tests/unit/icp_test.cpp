// Point-to-plane ICP and the normals it uses, on synthetic geometry with a known answer: normals of a
// plane are its normal, ICP brings a moved room corner (three planes fix all six degrees of freedom)
// back onto itself, alike far from the frame's origin, and without iterations it only measures the pose it
// is given.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>
#include <vector>

#include "k4reg/registration/icp.h"
#include "k4reg/registration/metrics.h"
#include "k4reg/geometry/neighbor_grid.h"

namespace k4reg {
namespace {

// Points on the planes x = 0, y = 0 and z = 0 (those listed), 0..3 m, on a jittered 2 cm lattice.
std::vector<Eigen::Vector3f> corner(bool with_floor, std::mt19937& rng) {
  std::uniform_real_distribution<float> jitter(-0.004f, 0.004f);
  std::vector<Eigen::Vector3f> points;
  for (float a = 0.01f; a < 3.0f; a += 0.02f)
    for (float b = 0.01f; b < 3.0f; b += 0.02f) {
      points.emplace_back(jitter(rng), a, b);
      points.emplace_back(a, jitter(rng), b);
      if (with_floor) points.emplace_back(a, b, jitter(rng));
    }
  return points;
}

Eigen::Matrix4d small_motion() {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = Eigen::AngleAxisd(2.0 * M_PI / 180.0, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  m.topRightCorner<3, 1>() = Eigen::Vector3d(0.06, -0.04, 0.05);
  return m;
}

std::vector<Eigen::Vector3f> moved(const std::vector<Eigen::Vector3f>& points, const Eigen::Matrix4d& m) {
  const Eigen::Affine3f a(m.cast<float>());
  std::vector<Eigen::Vector3f> out;
  for (const auto& p : points) out.push_back(a * p);
  return out;
}

TEST(Icp, NormalsOfAPlaneAreItsNormal) {
  std::mt19937 rng(1);
  std::vector<Eigen::Vector3f> plane;
  std::uniform_real_distribution<float> u(0.0f, 2.0f);
  for (int i = 0; i < 5000; ++i) plane.emplace_back(u(rng), u(rng), 0.0f);
  const NeighborGrid grid(plane, 0.1);
  const auto normals = estimate_normals(plane, grid, 0.1);
  ASSERT_EQ(normals.size(), plane.size());
  for (const auto& n : normals) EXPECT_NEAR(std::abs(n.z()), 1.0f, 1e-4f);
}

TEST(Icp, BringsAMovedCornerBack) {
  std::mt19937 rng(2);
  const auto target_points = corner(true, rng);
  const Eigen::Matrix4d truth = small_motion();
  const auto source_points = moved(corner(true, rng), truth.inverse());  // source = truth^-1 * target geometry
  IcpParams params;
  params.voxel_m = 0.02;
  const IcpPyramid source = make_icp_pyramid(source_points, params, PyramidRole::kSource);
  const IcpPyramid target = make_icp_pyramid(target_points, params, PyramidRole::kTarget);
  const IcpResult r = refine_icp(source, target, Eigen::Matrix4d::Identity(), params);
  EXPECT_TRUE(r.converged);
  const Eigen::Matrix4d error = truth.inverse() * r.transform;
  EXPECT_LT(rotation_angle_deg(error.topLeftCorner<3, 3>()), 0.05);
  const double translation_error_m = error.col(3).head<3>().norm();
  EXPECT_LT(translation_error_m, 0.002);
  EXPECT_GT(r.overlap, 0.9);
  EXPECT_LT(r.rmse_m, 0.005);
}

// The same corner and motion 40 m from the frame's origin (a file in shifted coordinates): ICP turns the source
// about its own centre, so it converges as at the origin, to the same pose. About the origin, each rotation
// step was a translation of metres and float rounding of the moved points a step noise above the bar.
TEST(Icp, ConvergesAlikeFarFromTheFramesOrigin) {
  std::mt19937 rng(2);
  const auto target_points = corner(true, rng);
  const Eigen::Matrix4d truth = small_motion();
  const auto source_points = moved(corner(true, rng), truth.inverse());
  Eigen::Matrix4d far = Eigen::Matrix4d::Identity();
  far.topRightCorner<3, 1>() = Eigen::Vector3d(30.0, -25.0, 8.0);
  IcpParams params;
  params.voxel_m = 0.02;
  auto run = [&](const Eigen::Matrix4d& placement) {
    return refine_icp(make_icp_pyramid(moved(source_points, placement), params, PyramidRole::kSource),
                      make_icp_pyramid(moved(target_points, placement), params, PyramidRole::kTarget),
                      Eigen::Matrix4d::Identity(), params);
  };
  const IcpResult at_origin = run(Eigen::Matrix4d::Identity()), away = run(far);
  ASSERT_TRUE(at_origin.converged);
  EXPECT_TRUE(away.converged);
  EXPECT_LE(away.iterations, at_origin.iterations + 2);
  const Eigen::Matrix4d error = (far * truth * far.inverse()).inverse() * away.transform;
  EXPECT_LT(rotation_angle_deg(error.topLeftCorner<3, 3>()), 0.05);
  EXPECT_LT((error.topLeftCorner<3, 3>() * Eigen::Vector3d(31.5, -23.5, 9.5) + error.col(3).head<3>() -
             Eigen::Vector3d(31.5, -23.5, 9.5)).norm(), 0.002);  // at the corner's centre
}

TEST(Icp, WithoutIterationsItOnlyMeasuresThePose) {
  // max_iterations = 0 (the --no-icp quality figures): the transform stays, and the figures tell a good
  // pose from one 10 cm off.
  std::mt19937 rng(3);
  const auto points = corner(true, rng);
  IcpParams params;
  params.voxel_m = 0.02;
  params.max_iterations = 0;
  const IcpPyramid source = make_icp_pyramid(points, params, PyramidRole::kSource);
  const IcpPyramid target = make_icp_pyramid(points, params, PyramidRole::kTarget);
  const IcpResult exact = refine_icp(source, target, Eigen::Matrix4d::Identity(), params);
  Eigen::Matrix4d off = Eigen::Matrix4d::Identity();
  off.topRightCorner<3, 1>() = Eigen::Vector3d(0.1, 0.0, 0.0);
  const IcpResult shifted = refine_icp(source, target, off, params);
  EXPECT_TRUE(shifted.transform.isApprox(off));
  EXPECT_LT(exact.rmse_m, 0.001);
  EXPECT_GT(exact.overlap, 0.99);
  EXPECT_LT(shifted.overlap, 0.8);  // the wall x = 0 moved 10 cm away from itself: beyond 2.5 voxels
}

}  // namespace
}  // namespace k4reg
