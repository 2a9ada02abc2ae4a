// NeighborGrid against brute force: every point within the radius is reported once with its squared
// distance, for radii within one cell (the one-look-up path), beyond it (the general loop), from
// queries inside the cloud, in the empty space next to it and far away.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "k4reg/geometry/neighbor_grid.h"

namespace k4reg {
namespace {

std::vector<Eigen::Vector3f> surface_and_clutter(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-2.0f, 2.0f);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 3000; ++i) points.emplace_back(u(rng), u(rng), 0.05f * u(rng));  // a noisy plane
  for (int i = 0; i < 500; ++i) points.emplace_back(u(rng), u(rng), u(rng));           // scattered points
  return points;
}

std::vector<std::pair<std::uint32_t, float>> brute_force(const std::vector<Eigen::Vector3f>& points,
                                                         const Eigen::Vector3f& q, float radius) {
  std::vector<std::pair<std::uint32_t, float>> found;
  for (std::uint32_t i = 0; i < points.size(); ++i) {
    const float d2 = (points[i] - q).squaredNorm();
    if (d2 <= radius * radius) found.emplace_back(i, d2);
  }
  return found;
}

TEST(NeighborGrid, FindsExactlyThePointsWithinTheRadius) {
  std::mt19937 rng(7);
  const auto points = surface_and_clutter(rng);
  const double cell = 0.3;
  const NeighborGrid grid(points, cell);
  std::uniform_real_distribution<float> u(-3.0f, 3.0f);
  std::size_t checked = 0, found_any = 0;
  for (const float radius : {0.05f, 0.15f, 0.3f, 0.45f, 0.9f}) {
    for (int k = 0; k < 300; ++k) {
      const Eigen::Vector3f q = k % 3 == 0 ? points[k] : Eigen::Vector3f(u(rng), u(rng), u(rng));
      std::vector<std::pair<std::uint32_t, float>> got;
      grid.for_each_within(q, radius, [&](std::uint32_t i, float d2) { got.emplace_back(i, d2); });
      auto expected = brute_force(points, q, radius);
      std::sort(got.begin(), got.end());
      ASSERT_EQ(got.size(), expected.size()) << "radius " << radius << " query " << q.transpose();
      for (std::size_t i = 0; i < got.size(); ++i) {
        EXPECT_EQ(got[i].first, expected[i].first);
        EXPECT_FLOAT_EQ(got[i].second, expected[i].second);
      }
      ++checked;
      found_any += !got.empty();
    }
  }
  EXPECT_EQ(checked, 1500u);
  EXPECT_GT(found_any, 500u);  // the queries did exercise non-empty neighbourhoods
}

TEST(NeighborGrid, NearestWithinIsTheClosestPointOrNone) {
  std::mt19937 rng(11);
  const auto points = surface_and_clutter(rng);
  const NeighborGrid grid(points, 0.25);
  std::uniform_real_distribution<float> u(-2.5f, 2.5f);
  for (int k = 0; k < 500; ++k) {
    const Eigen::Vector3f q(u(rng), u(rng), 0.3f * u(rng));
    float d2 = 0;
    const int got = grid.nearest_within(q, 0.25f, &d2);
    const auto within = brute_force(points, q, 0.25f);
    if (within.empty()) {
      EXPECT_EQ(got, -1);
      continue;
    }
    const auto best = std::min_element(within.begin(), within.end(),
                                       [](const auto& a, const auto& b) { return a.second < b.second; });
    ASSERT_GE(got, 0);
    EXPECT_FLOAT_EQ(d2, best->second);
  }
  // Far from every point: nothing, without touching the cloud.
  EXPECT_EQ(grid.nearest_within(Eigen::Vector3f(100.0f, 100.0f, 100.0f), 0.25f), -1);
  EXPECT_FALSE(grid.any_within(Eigen::Vector3f(0.0f, 0.0f, 50.0f), 0.2f));
}

TEST(NeighborGrid, OneCellAndGeneralPathsVisitInTheSameOrder) {
  // Sums over neighbours (the DoG) must not depend on which path a query takes: a radius just within
  // one cell and the same radius on a grid whose cell is slightly smaller (general loop) see the same
  // neighbours in the same order.
  std::mt19937 rng(3);
  const auto points = surface_and_clutter(rng);
  const NeighborGrid one_cell(points, 0.4);
  for (int k = 0; k < 200; ++k) {
    const Eigen::Vector3f q = points[k * 7];
    std::vector<std::uint32_t> fast, general;
    one_cell.for_each_within(q, 0.4f, [&](std::uint32_t i, float) { fast.push_back(i); });
    // The general loop runs when the radius exceeds the cell; restrict it back to 0.4 m.
    one_cell.for_each_within(q, 0.4001f, [&](std::uint32_t i, float d2) {
      if (d2 <= 0.4f * 0.4f) general.push_back(i);
    });
    EXPECT_EQ(fast, general);
  }
}

// A grid built for few queries (the congruent-set search's) takes the general loop, whose empty cells end in
// KeyBits: still every point within the radius, and only those.
TEST(NeighborGrid, AGridForFewQueriesFindsExactlyThePointsWithinTheRadius) {
  std::mt19937 rng(3);
  const std::vector<Eigen::Vector3f> points = surface_and_clutter(rng);
  const NeighborGrid grid(points, 0.1, NeighborGrid::Queries::kFew);
  std::uniform_real_distribution<float> u(-2.5f, 2.5f);
  for (int k = 0; k < 300; ++k) {
    const Eigen::Vector3f q(u(rng), u(rng), 0.2f * u(rng));
    std::vector<std::pair<std::uint32_t, float>> got;
    grid.for_each_within(q, 0.1f, [&](std::uint32_t i, float d2) { got.emplace_back(i, d2); });
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, brute_force(points, q, 0.1f)) << "query " << q.transpose();
  }
}

TEST(KeyBits, HoldsEveryKeyAddedAndFewOthers) {
  KeyBits bits(1000);
  for (std::uint64_t key = 0; key < 1000; ++key) bits.add(key * 7919);
  for (std::uint64_t key = 0; key < 1000; ++key) EXPECT_TRUE(bits.may_hold(key * 7919));
  int false_positives = 0;
  for (std::uint64_t key = 0; key < 100000; ++key) false_positives += bits.may_hold(key * 7919 + 1);
  EXPECT_LT(false_positives, 10000);  // about 16 bits per key: ~6 % of absent keys pass
}

}  // namespace
}  // namespace k4reg
