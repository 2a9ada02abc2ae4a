// How firmly matched surfaces pin a translation (translation_constraint.h): a corridor leaves its axis free, a
// closed room pins every direction, and the figures follow a rotation into another frame.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "k4reg/registration/icp.h"
#include "k4reg/registration/translation_constraint.h"

namespace k4reg {
namespace {

// Points every 5 cm on the axis-aligned rectangle `fixed` = value, spanning [lo, hi] in the other two axes.
void add_plane(std::vector<Eigen::Vector3f>& points, int fixed, float value, const Eigen::Vector3f& lo,
               const Eigen::Vector3f& hi) {
  const int u = (fixed + 1) % 3, v = (fixed + 2) % 3;
  for (float a = lo[u]; a <= hi[u]; a += 0.05f)
    for (float b = lo[v]; b <= hi[v]; b += 0.05f) {
      Eigen::Vector3f p;
      p[fixed] = value, p[u] = a, p[v] = b;
      points.push_back(p);
    }
}

Eigen::Matrix3d constraint_of(const std::vector<Eigen::Vector3f>& points) {
  IcpParams params;
  params.voxel_m = 0.1;
  params.stages = 1;
  const IcpPyramid source = make_icp_pyramid(points, params, PyramidRole::kSource),
                   target = make_icp_pyramid(points, params, PyramidRole::kTarget);
  return normalized_constraint(refine_icp(source, target, Eigen::Matrix4d::Identity(), params).translation_information);
}

TEST(TranslationConstraint, CorridorLeavesItsAxisFreeAndARoomPinsEveryDirection) {
  const Eigen::Vector3f lo(-5, -1, 0), hi(5, 1, 2.5);
  std::vector<Eigen::Vector3f> corridor;  // two walls, floor and ceiling along x
  add_plane(corridor, 1, -1, lo, hi);
  add_plane(corridor, 1, 1, lo, hi);
  add_plane(corridor, 2, 0, lo, hi);
  add_plane(corridor, 2, 2.5f, lo, hi);
  const Eigen::Matrix3d c = constraint_of(corridor);
  EXPECT_NEAR(c.trace(), 3.0, 1e-9);
  const std::array<double, 3> axis = axis_constraint(c);
  EXPECT_LT(axis[0], 0.05) << "free along the corridor";
  EXPECT_GT(axis[1], 1.2);
  EXPECT_GT(axis[2], 1.2);
  EXPECT_LT(weakest_constraint(c), 0.05);

  std::vector<Eigen::Vector3f> room = corridor;  // the corridor closed by its two end walls
  add_plane(room, 0, -5, lo, hi);
  add_plane(room, 0, 5, lo, hi);
  const Eigen::Matrix3d closed = constraint_of(room);
  EXPECT_GT(weakest_constraint(closed), 0.2);
  EXPECT_GT(axis_constraint(closed)[0], 0.2);

  // In a frame turned 90 degrees about z the free direction is y.
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3d turned = rotated_constraint(c, turn);
  EXPECT_LT(axis_constraint(turned)[1], 0.05);
  EXPECT_NEAR(weakest_constraint(turned), weakest_constraint(c), 1e-9);
}

TEST(TranslationConstraint, NoInformationIsNoConstraint) {
  EXPECT_TRUE(normalized_constraint(Eigen::Matrix3d::Zero()).isZero());
  EXPECT_DOUBLE_EQ(weakest_constraint(Eigen::Matrix3d::Zero()), 0.0);
  EXPECT_NEAR(weakest_constraint(Eigen::Matrix3d::Identity()), 1.0, 1e-12);
}

}  // namespace
}  // namespace k4reg
