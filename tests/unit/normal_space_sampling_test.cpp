// Normal-space sampling: every surface orientation is represented, however few points it has.
#include "k4reg/geometry/normal_space_sampling.h"

#include <gtest/gtest.h>

#include <cmath>

namespace k4reg {
namespace {

TEST(NormalSpaceSampling, AFewWallPointsAreNotOutnumberedByTheGround) {
  std::vector<Eigen::Vector3f> points, normals;
  for (int i = 0; i < 100000; ++i) points.emplace_back(i % 300 * 0.1f, i / 300 * 0.1f, 0.0f), normals.emplace_back(0, 0, 1);
  for (int i = 0; i < 2000; ++i) points.emplace_back(5.0f, i % 40 * 0.1f, 1.0f + i / 40 * 0.1f), normals.emplace_back(1, 0, 0);
  const auto sample = normal_space_sample(points, normals, 1000);
  ASSERT_LE(sample.size(), 1000u);
  EXPECT_GE(sample.size(), 990u);
  int wall = 0;
  for (const Eigen::Vector3f& p : sample) wall += p.z() > 0.5f;
  // Two orientations, two equal shares: the wall gives half the sample, not 2 %.
  EXPECT_EQ(wall, static_cast<int>(sample.size()) / 2);
}

TEST(NormalSpaceSampling, OppositeNormalsShareABinAndPointsWithoutANormalAreLeftOut) {
  std::vector<Eigen::Vector3f> points, normals;
  for (int i = 0; i < 100; ++i) points.emplace_back(i, 0, 0), normals.emplace_back(0, 0, i % 2 ? 1.0f : -1.0f);
  for (int i = 0; i < 100; ++i) points.emplace_back(i, 1, 0), normals.emplace_back(0, 0, 0);
  const auto sample = normal_space_sample(points, normals, 30);
  EXPECT_EQ(sample.size(), 30u);
  for (const Eigen::Vector3f& p : sample) EXPECT_EQ(p.y(), 0.0f);
  // Fewer points than asked for: all of them.
  EXPECT_EQ(normal_space_sample(points, normals, 1000).size(), 100u);
  EXPECT_TRUE(normal_space_sample({}, {}, 10).empty());
}

}  // namespace
}  // namespace k4reg
