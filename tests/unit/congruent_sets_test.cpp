// The 4PCS building blocks: the length-sorted pair index against brute force and its memory bound,
// congruent sets (the base's own correspondences are among them; dense grids are capped), cancellation.
#include "k4reg/registration/congruent_sets.h"

#include <gtest/gtest.h>

#include <random>

#include "k4reg/util/error.h"
#include "error_code_of.h"

namespace k4reg {
namespace {

std::vector<Eigen::Vector3f> random_points(int n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 10.0f);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < n; ++i) points.emplace_back(u(rng), u(rng), 0.2f * u(rng));
  return points;
}

std::vector<Eigen::Vector3f> regular_grid(int side, float spacing) {
  std::vector<Eigen::Vector3f> points;
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) points.emplace_back(spacing * x, spacing * y, 0.0f);
  return points;
}

TEST(PairIndex, ReturnsExactlyThePairsOfAGivenLength) {
  const auto points = random_points(400, 1);
  const PairIndex index(points, 2.0, 6.0);
  for (const double length : {2.5, 4.0, 5.9}) {
    const auto [first, last] = index.with_length(length, 0.05);
    std::size_t expected = 0;
    for (std::size_t i = 0; i < points.size(); ++i)
      for (std::size_t j = i + 1; j < points.size(); ++j) {
        const float d = (points[i] - points[j]).norm();
        expected += d >= 2.0f && d <= 6.0f && std::abs(d - length) <= 0.05f;
      }
    EXPECT_EQ(static_cast<std::size_t>(last - first), expected) << "length " << length;
    for (auto p = first; p != last; ++p) EXPECT_NEAR((points[p->i] - points[p->j]).norm(), length, 0.05 + 1e-5);
  }
}

TEST(PairIndex, RefusesMorePairsThanItsBudget) {
  const auto points = random_points(600, 2);  // about 60 000 pairs within the band
  EXPECT_EQ(test::error_code_of([&] { PairIndex(points, 0.0, 100.0, nullptr, 10000); }), ErrorCode::kResourceExhausted);
  EXPECT_NO_THROW(PairIndex(points, 0.0, 100.0, nullptr, 1000000));
}

TEST(PairIndex, StopsWhenCancelled) {
  CancellationToken cancel;
  cancel.cancel();
  const auto points = random_points(100, 3);
  EXPECT_EQ(test::error_code_of([&] { PairIndex(points, 0.0, 100.0, &cancel); }), ErrorCode::kCancelled);
}

// A base on the grid and its own points must be among the congruent sets; a regular grid matches
// combinatorially many sets, which max_sets bounds.
TEST(CongruentSets, FindsTheBaseItselfAndHonoursTheCap) {
  const auto grid = regular_grid(30, 0.5f);  // 900 points, 15 x 15 m
  Base base;
  base.index = {0, 29 * 30 + 29, 29, 29 * 30};  // the two diagonals of the square
  for (int k = 0; k < 4; ++k) base.point[k] = grid[base.index[k]];
  base.r1 = base.r2 = 0.5f;
  base.length1 = (base.point[1] - base.point[0]).norm();
  base.length2 = (base.point[3] - base.point[2]).norm();
  const CongruenceTolerances tolerance = CongruenceTolerances::from_delta(0.1);
  const PairIndex pairs(grid, 10.0, 25.0);
  std::vector<Quadrilateral> sets;
  find_congruent_sets(base, grid, pairs, tolerance, 1000000, sets);
  const Quadrilateral itself{base.index[0], base.index[1], base.index[2], base.index[3]};
  EXPECT_NE(std::find(sets.begin(), sets.end(), itself), sets.end());

  // A smaller base fits in many places on the grid: the cap holds.
  base.index = {0, 10 * 30 + 10, 10, 10 * 30};
  for (int k = 0; k < 4; ++k) base.point[k] = grid[base.index[k]];
  base.length1 = (base.point[1] - base.point[0]).norm();
  base.length2 = (base.point[3] - base.point[2]).norm();
  const PairIndex short_pairs(grid, 4.0, 8.0);
  std::vector<Quadrilateral> all, capped;
  find_congruent_sets(base, grid, short_pairs, tolerance, 1000000, all);
  find_congruent_sets(base, grid, short_pairs, tolerance, 50, capped);
  ASSERT_GT(all.size(), 50u);
  EXPECT_EQ(capped.size(), 50u);
}

TEST(CongruentSets, StopsWhenCancelled) {
  const auto grid = regular_grid(30, 0.5f);
  Base base;
  base.index = {0, 10 * 30 + 10, 10, 10 * 30};
  for (int k = 0; k < 4; ++k) base.point[k] = grid[base.index[k]];
  base.r1 = base.r2 = 0.5f;
  base.length1 = (base.point[1] - base.point[0]).norm();
  base.length2 = (base.point[3] - base.point[2]).norm();
  const PairIndex pairs(grid, 4.0, 8.0);
  CancellationToken cancel;
  cancel.cancel();
  std::vector<Quadrilateral> sets;
  const CongruenceTolerances tolerance = CongruenceTolerances::from_delta(0.1);
  EXPECT_EQ(test::error_code_of([&] { find_congruent_sets(base, grid, pairs, tolerance, 1000, sets, &cancel); }),
            ErrorCode::kCancelled);
}

}  // namespace
}  // namespace k4reg
