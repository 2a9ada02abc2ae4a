#include "k4reg/geometry/voxel_grid.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <map>
#include <random>
#include <tuple>

#include "k4reg/util/error.h"

namespace k4reg {
namespace {

PointCloud random_cloud(std::size_t n, float extent, bool intensity, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(-extent, extent);
  PointCloud cloud;
  for (std::size_t i = 0; i < n; ++i) {
    cloud.points.emplace_back(u(rng), u(rng), u(rng));
    if (intensity) cloud.intensity.push_back(u(rng));
  }
  return cloud;
}

// Brute force: a std::map from integer voxel coordinates to sums.
struct Reference {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double intensity = 0;
  std::uint32_t count = 0;
};
std::map<std::tuple<int, int, int>, Reference> brute_force(const PointCloud& cloud, double voxel) {
  std::map<std::tuple<int, int, int>, Reference> voxels;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f& p = cloud.points[i];
    auto key = std::make_tuple(int(std::floor(p.x() / voxel)), int(std::floor(p.y() / voxel)), int(std::floor(p.z() / voxel)));
    Reference& r = voxels[key];
    r.sum += p.cast<double>();
    if (cloud.has_intensity()) r.intensity += cloud.intensity[i];
    ++r.count;
  }
  return voxels;
}

TEST(VoxelGrid, MatchesBruteForceCentroidsCountsAndIntensity) {
  const PointCloud cloud = random_cloud(600000, 3.0f, true, 7);  // several chunks, shared voxels between them
  const double voxel = 0.25;
  const VoxelizedCloud out = voxel_grid(cloud, voxel);
  const auto reference = brute_force(cloud, voxel);
  ASSERT_EQ(out.cloud.size(), reference.size());
  ASSERT_TRUE(out.cloud.has_intensity());
  std::size_t total = 0;
  for (std::size_t v = 0; v < out.cloud.size(); ++v) {
    const Eigen::Vector3f& c = out.cloud.points[v];
    // Centroids lie inside their voxel, so the voxel of a centroid identifies it.
    auto key = std::make_tuple(int(std::floor(c.x() / voxel)), int(std::floor(c.y() / voxel)), int(std::floor(c.z() / voxel)));
    const auto it = reference.find(key);
    ASSERT_NE(it, reference.end());
    EXPECT_EQ(out.counts[v], it->second.count);
    EXPECT_LT((c.cast<double>() - it->second.sum / it->second.count).norm(), 1e-5);
    EXPECT_NEAR(out.cloud.intensity[v], it->second.intensity / it->second.count, 1e-5);
    total += out.counts[v];
  }
  EXPECT_EQ(total, cloud.size());
}

TEST(VoxelGrid, SameOutputForAnyThreadCount) {
  const PointCloud cloud = random_cloud(700000, 2.0f, false, 3);
  VoxelizedCloud one, two;
  tbb::task_arena(1).execute([&] { one = voxel_grid(cloud, 0.1); });
  tbb::task_arena(2).execute([&] { two = voxel_grid(cloud, 0.1); });
  ASSERT_EQ(one.cloud.size(), two.cloud.size());
  for (std::size_t v = 0; v < one.cloud.size(); ++v) {
    ASSERT_EQ(one.cloud.points[v], two.cloud.points[v]);
    ASSERT_EQ(one.counts[v], two.counts[v]);
  }
}

TEST(VoxelGrid, KilometreSceneAtCentimetreVoxels) {
  // 1 km extent at 1 cm: 1e5 voxels per axis, 1e15 cells in all; PCL's VoxelGrid refuses this.
  PointCloud cloud;
  for (int i = 0; i <= 1000; ++i) cloud.points.emplace_back(i - 500.0f + 0.003f, 0.004f, -400.0f + 0.8f * i);
  const VoxelizedCloud out = voxel_grid(cloud, 0.01);
  EXPECT_EQ(out.cloud.size(), cloud.size());
}

TEST(VoxelGrid, RejectsBadVoxelSizeAndHugeExtent) {
  PointCloud cloud = random_cloud(10, 1.0f, false, 1);
  EXPECT_THROW(voxel_grid(cloud, 0.0), Error);
  EXPECT_THROW(voxel_grid(cloud, -1.0), Error);
  EXPECT_THROW(voxel_grid(cloud, NAN), Error);
  cloud.points.emplace_back(5e4f, 0.0f, 0.0f);  // 50 km at 1 cm needs more than 2^21 voxels
  try {
    voxel_grid(cloud, 0.01);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
  }
}

TEST(VoxelGrid, EmptyCloudGivesNoVoxels) {
  EXPECT_EQ(voxel_grid(PointCloud{}, 0.1).cloud.size(), 0u);
}

}  // namespace
}  // namespace k4reg
