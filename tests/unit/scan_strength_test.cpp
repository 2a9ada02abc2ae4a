// The minimum cut that holds a scan to the reference: margins of independent pairs add up, a chain is as
// strong as its weakest link, a scan reached through nothing is not held at all, and the scans on a weakly held
// scan's side of the cut move with it.
#include <gtest/gtest.h>

#include "k4reg/project/scan_strength.h"

namespace k4reg {
namespace {

std::vector<double> strengths(std::size_t scans, const std::vector<WeightedLink>& links, std::size_t reference, double cap) {
  std::vector<double> out;
  for (const ScanHold& h : scan_holds(scans, links, reference, cap)) out.push_back(h.strength);
  return out;
}

TEST(ScanStrength, MarginsOfParallelLinksAddUpAndChainsTakeTheWeakest) {
  // 0 - 1 directly (0.03) and through 2 (0.04 then 0.02); 3 hangs off 1 by 0.5; 4 is alone.
  const std::vector<WeightedLink> links{{0, 1, 0.03}, {0, 2, 0.04}, {2, 1, 0.02}, {1, 3, 0.5}};
  const std::vector<double> s = strengths(5, links, 0, 1.0);
  EXPECT_DOUBLE_EQ(s[0], 1.0);
  EXPECT_NEAR(s[1], 0.05, 1e-12);  // 0.03 + min(0.04, 0.02)
  EXPECT_NEAR(s[2], 0.06, 1e-12);  // 0.04 + min(0.03, 0.02)
  EXPECT_NEAR(s[3], 0.05, 1e-12);  // everything reaching 1 goes on to 3
  EXPECT_EQ(s[4], 0.0);
}

TEST(ScanStrength, CapStopsTheFlowAndReferenceCanBeAnyScan) {
  const std::vector<WeightedLink> links{{0, 1, 0.7}, {0, 1, 0.7}, {1, 2, 0.01}};
  const std::vector<double> s = strengths(3, links, 1, 0.5);
  EXPECT_DOUBLE_EQ(s[0], 0.5);
  EXPECT_DOUBLE_EQ(s[1], 0.5);
  EXPECT_NEAR(s[2], 0.01, 1e-12);
}

TEST(ScanStrength, FourScansOfASymmetricHallWithSmallMarginsEach) {
  // Every pair at margin 0.02 (each alone ambiguous): a scan's three links together hold it at 0.06.
  std::vector<WeightedLink> links;
  for (std::size_t a = 0; a < 4; ++a)
    for (std::size_t b = a + 1; b < 4; ++b) links.push_back({a, b, 0.02});
  for (double s : strengths(4, links, 0, 1.0)) EXPECT_GE(s, 0.06 - 1e-12);
}

TEST(ScanStrength, AWeaklyHeldScanMovesWithItsSideOfTheCheapestCut) {
  // Hall layout 3 as measured: the reference 0 holds 1, 2 and 3 by 0.0215, 0.0134 and 0.0141, while 1, 2 and 3 hold
  // one another firmly (confirmed links). The cheapest move turns all three together; 4 hangs off 3 by 0.02 alone.
  const std::vector<WeightedLink> links{{0, 1, 0.0215}, {0, 2, 0.0134}, {0, 3, 0.0141}, {1, 2, 0.05},
                                        {1, 3, 0.05},   {2, 3, 0.05},   {3, 4, 0.02}};
  const std::vector<ScanHold> h = scan_holds(5, links, 0, 1.0);
  EXPECT_TRUE(h[0].moves_with.empty());
  for (std::size_t i : {1, 2, 3}) {
    EXPECT_NEAR(h[i].strength, 0.049, 1e-12) << i;
    EXPECT_EQ(h[i].moves_with, (std::vector<std::size_t>{1, 2, 3, 4})) << i;  // 4 cannot stay without 3
  }
  EXPECT_NEAR(h[4].strength, 0.02, 1e-12);
  EXPECT_EQ(h[4].moves_with, std::vector<std::size_t>{4});  // cheaper to turn 4 alone
  // Held to the cap: nothing moves with it.
  const std::vector<ScanHold> firm = scan_holds(2, {{0, 1, 2.0}}, 0, 1.0);
  EXPECT_DOUBLE_EQ(firm[1].strength, 1.0);
  EXPECT_TRUE(firm[1].moves_with.empty());
}

}  // namespace
}  // namespace k4reg
