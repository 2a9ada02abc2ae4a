// The translation vote: for a known rotation, the shift where structure meets structure.
#include "k4reg/registration/translation_vote.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace k4reg {
namespace {

// A box of 1 m standing at `at` on nothing else: points on its faces every 0.1 m.
std::vector<Eigen::Vector3f> box(const Eigen::Vector3f& at) {
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i <= 10; ++i)
    for (int j = 0; j <= 10; ++j)
      for (int face = 0; face < 3; ++face) {
        Eigen::Vector3f p(i * 0.1f, j * 0.1f, 0.0f), q = p;
        std::swap(q(face), q(2));
        points.push_back(at + q);
        q(face) = 1.0f;
        points.push_back(at + q);
      }
  return points;
}

TEST(TranslationVote, FindsTheShiftOfARotatedObject) {
  const std::vector<Eigen::Vector3f> target = box({4, -2, 1});
  const Eigen::Matrix3d r = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d shift(1.5, -0.5, 2.0);
  std::vector<Eigen::Vector3f> source;  // target = r * source + shift
  for (const Eigen::Vector3f& q : target) source.push_back((r.transpose() * (q.cast<double>() - shift)).cast<float>());
  const auto shifts = vote_translations(source, target, r, 0.2, 3);
  ASSERT_EQ(shifts.size(), 3u);
  // The winner is the cell whose 3 x 3 x 3 block has the most votes: within about a cell on each axis.
  EXPECT_LT((shifts[0] - shift).cwiseAbs().maxCoeff(), 0.25);
  // The runner-ups are more than a cell away from the winner.
  for (std::size_t i = 1; i < shifts.size(); ++i) EXPECT_GT((shifts[i] - shifts[0]).cwiseAbs().maxCoeff(), 0.2);
}

TEST(TranslationVote, IsDeterministicAndEmptyForNoPoints) {
  const std::vector<Eigen::Vector3f> target = box({0, 0, 0});
  const auto a = vote_translations(target, target, Eigen::Matrix3d::Identity(), 0.25, 4);
  const auto b = vote_translations(target, target, Eigen::Matrix3d::Identity(), 0.25, 4);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i], b[i]);
  EXPECT_LT(a[0].norm(), 0.25);
  EXPECT_TRUE(vote_translations({}, target, Eigen::Matrix3d::Identity(), 0.25, 4).empty());
}

// Votes are counted in an array over the box of possible shifts, or in a hash map where that box is too
// large (a stray point kilometres away): both count the same cells, so the answer is the same.
TEST(TranslationVote, AFarStrayPointChangesNothing) {
  const std::vector<Eigen::Vector3f> target = box({4, -2, 1});
  const Eigen::Matrix3d r = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  std::vector<Eigen::Vector3f> source;
  for (const Eigen::Vector3f& q : target) source.push_back((r.transpose() * (q.cast<double>() - Eigen::Vector3d(1.03, 2.04, 0.02))).cast<float>());
  std::vector<Eigen::Vector3f> stray = target;
  stray.emplace_back(3000.0f, -2000.0f, 500.0f);  // 3 km x 2 km x 0.5 km of shifts at 0.1 m: 3e12 cells
  const auto near = vote_translations(source, target, r, 0.1, 3), far = vote_translations(source, stray, r, 0.1, 3);
  ASSERT_EQ(near.size(), 3u);
  ASSERT_EQ(far.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(near[i], far[i]) << i;
  EXPECT_LT((near[0] - Eigen::Vector3d(1.03, 2.04, 0.02)).cwiseAbs().maxCoeff(), 0.15);
}

// A row of equal boxes 4 m apart (a corridor's doors), the first seen four times as densely (near the
// scanner): one box of the source fits each of them, but the dense copy's near misses outvote the others'
// exact fits. Peaks a cell apart crowd around the dense copy; kept further apart, there is one per box.
TEST(TranslationVote, SeparatedPeaksFindEveryCopyOfARepeatedObject) {
  std::vector<Eigen::Vector3f> target;
  for (const float x : {0.0f, 4.0f, 8.0f}) {
    const std::vector<Eigen::Vector3f> one = box({x, 0, 0});
    for (int copy = 0; copy < (x == 0.0f ? 4 : 1); ++copy) target.insert(target.end(), one.begin(), one.end());
  }
  const std::vector<Eigen::Vector3f> source = box({0, 0, 0});
  const auto crowded = vote_translations(source, target, Eigen::Matrix3d::Identity(), 0.2, 3, 1);
  const auto apart = vote_translations(source, target, Eigen::Matrix3d::Identity(), 0.2, 3, 6);
  ASSERT_EQ(apart.size(), 3u);
  std::vector<double> found;
  for (const Eigen::Vector3d& shift : apart) {
    EXPECT_LT(std::abs(shift.y()) + std::abs(shift.z()), 0.4);
    found.push_back(shift.x());
  }
  std::sort(found.begin(), found.end());
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(found[i], 4.0 * static_cast<double>(i), 0.25) << i;
  ASSERT_EQ(crowded.size(), 3u);
  for (const Eigen::Vector3d& shift : crowded) EXPECT_LT((shift - crowded[0]).norm(), 1.0);
}

}  // namespace
}  // namespace k4reg
