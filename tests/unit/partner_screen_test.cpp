// The partner screen of large projects: which pairs it keeps for given estimates, and that its estimates tell
// overlapping scans (neighbouring bunny views) from scans that barely overlap (opposite views).
#include "k4reg/project/partner_screen.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "k4reg/io/cloud_io.h"
#include "k4reg/util/error.h"

namespace k4reg {
namespace {

// Estimates for every pair of `scans` from a function of the two indices, in candidate_pairs(kAll) order.
template <typename F>
std::vector<double> estimates_of(std::size_t scans, F f) {
  std::vector<double> e;
  for (const auto& [a, b] : candidate_pairs(scans, PairSelection::kAll)) e.push_back(f(a, b));
  return e;
}

bool has(const std::vector<ScanPair>& pairs, std::size_t a, std::size_t b) {
  return std::find(pairs.begin(), pairs.end(), ScanPair{a, b}) != pairs.end();
}

// Eight stations in a ring: neighbours overlap most, the next ones less, the rest barely.
double ring(std::size_t a, std::size_t b) {
  const std::size_t d = std::min(b - a, 8 - (b - a));
  return d == 1 ? 0.6 : d == 2 ? 0.4 : 0.05;
}

TEST(BestPartners, EachScanKeepsItsBestPartners) {
  const std::vector<ScanPair> two = best_partners(8, estimates_of(8, ring), 2);
  EXPECT_EQ(two.size(), 8u);  // the ring's neighbours
  for (std::size_t i = 0; i < 8; ++i) EXPECT_TRUE(has(two, std::min(i, (i + 1) % 8), std::max(i, (i + 1) % 8))) << i;
  const std::vector<ScanPair> four = best_partners(8, estimates_of(8, ring), 4);
  EXPECT_EQ(four.size(), 16u);  // and the next ones: every three consecutive stations close a loop
  EXPECT_TRUE(has(four, 0, 2) && has(four, 0, 6) && !has(four, 0, 4));
  EXPECT_TRUE(std::is_sorted(four.begin(), four.end()));
}

TEST(BestPartners, JoinsGroupsThatOnlyTheirBestCrossPairConnects) {
  // Two rooms of four scans; the doorway pair 2-5 sees a little of both, 1-6 less.
  const auto rooms = [](std::size_t a, std::size_t b) {
    if ((a < 4) == (b < 4)) return 0.5;
    return a == 2 && b == 5 ? 0.1 : a == 1 && b == 6 ? 0.05 : 0.0;
  };
  const std::vector<ScanPair> pairs = best_partners(8, estimates_of(8, rooms), 3);
  EXPECT_TRUE(has(pairs, 2, 5));
  EXPECT_FALSE(has(pairs, 1, 6));
  EXPECT_EQ(pairs.size(), 13u);  // both rooms' six pairs, and the doorway
}

TEST(BestPartners, AScanThatOverlapsNothingStillGetsItsPartners) {
  // Scan 4 matches nothing: it is still tried with `partners` others (ties to the lower index), never dropped.
  const auto e = estimates_of(5, [](std::size_t a, std::size_t b) { return b == 4 ? 0.0 : 0.3 + 0.01 * (a + b); });
  const std::vector<ScanPair> pairs = best_partners(5, e, 2);
  EXPECT_TRUE(has(pairs, 0, 4) && has(pairs, 1, 4));
  EXPECT_FALSE(has(pairs, 2, 4) || has(pairs, 3, 4));
  EXPECT_THROW(best_partners(5, {0.1, 0.2}, 2), Error);
}

TEST(MorePartners, TheNextBestPartnersOfTheScansToExtendOnly) {
  const std::vector<double> e = estimates_of(8, ring);
  const std::vector<ScanPair> first = best_partners(8, e, 2);  // the ring's neighbours
  // Scan 0's next best are 2 and 6 (0.4 each); scan 5's are 3 and 7. Nothing already chosen comes back.
  EXPECT_EQ(more_partners(8, e, first, {0, 5}, 2), (std::vector<ScanPair>{{0, 2}, {0, 6}, {3, 5}, {5, 7}}));
  EXPECT_TRUE(more_partners(8, e, first, {}, 2).empty());
}

TEST(PairSelection, AutoIsAllPairsUpToSixteenScansAndScreenedBeyond) {
  EXPECT_EQ(resolved(PairSelection::kAuto, kAllPairsUpTo), PairSelection::kAll);
  EXPECT_EQ(resolved(PairSelection::kAuto, kAllPairsUpTo + 1), PairSelection::kScreened);
  EXPECT_EQ(resolved(PairSelection::kSequence, 100), PairSelection::kSequence);
  EXPECT_STREQ(to_string(PairSelection::kScreened), "screened");
  // The screened selections need the scans.
  EXPECT_THROW(candidate_pairs(4, PairSelection::kScreened), Error);
  EXPECT_THROW(candidate_pairs(4, PairSelection::kAuto), Error);
}

TEST(EstimateOverlaps, NeighbouringViewsOverlapMoreThanOppositeOnesAtAnyThreadCount) {
  const std::string dir = std::string(K4REG_TEST_DATA_DIR) + "/bunny/";
  // bun000 and bun045 are 45 degrees apart; bun180 looks at the bunny from behind.
  const std::vector<PointCloud> clouds{read_cloud(dir + "bun000.ply"), read_cloud(dir + "bun045.ply"),
                                       read_cloud(dir + "bun180.ply")};
  RegistrationParams params;
  params.min_scale_m = 0.002;
  params.seed = 1;
  params.threads = 1;
  const std::vector<PreparedScan> scans(clouds.begin(), clouds.end());
  const std::vector<double> one = estimate_overlaps(scans, params);  // (0,1), (0,2), (1,2)
  ASSERT_EQ(one.size(), 3u);
  EXPECT_GT(one[0], 0.2);
  EXPECT_GT(one[0], 2.0 * one[1]) << "bun000-bun045 " << one[0] << ", bun000-bun180 " << one[1];
  params.threads = 2;
  const std::vector<PreparedScan> again(clouds.begin(), clouds.end());
  EXPECT_EQ(estimate_overlaps(again, params), one);
}

}  // namespace
}  // namespace k4reg
