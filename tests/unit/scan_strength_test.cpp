// The minimum cut that holds a scan to the reference: margins of independent pairs add up, a chain is as
// strong as its weakest link, and a scan reached through nothing is not held at all.
#include <gtest/gtest.h>

#include "k4reg/project/scan_strength.h"

namespace k4reg {
namespace {

TEST(ScanStrength, MarginsOfParallelLinksAddUpAndChainsTakeTheWeakest) {
  // 0 - 1 directly (0.03) and through 2 (0.04 then 0.02); 3 hangs off 1 by 0.5; 4 is alone.
  const std::vector<WeightedLink> links{{0, 1, 0.03}, {0, 2, 0.04}, {2, 1, 0.02}, {1, 3, 0.5}};
  const std::vector<double> s = scan_strengths(5, links, 0, 1.0);
  EXPECT_DOUBLE_EQ(s[0], 1.0);
  EXPECT_NEAR(s[1], 0.05, 1e-12);  // 0.03 + min(0.04, 0.02)
  EXPECT_NEAR(s[2], 0.06, 1e-12);  // 0.04 + min(0.03, 0.02)
  EXPECT_NEAR(s[3], 0.05, 1e-12);  // everything reaching 1 goes on to 3
  EXPECT_EQ(s[4], 0.0);
}

TEST(ScanStrength, CapStopsTheFlowAndReferenceCanBeAnyScan) {
  const std::vector<WeightedLink> links{{0, 1, 0.7}, {0, 1, 0.7}, {1, 2, 0.01}};
  const std::vector<double> s = scan_strengths(3, links, 1, 0.5);
  EXPECT_DOUBLE_EQ(s[0], 0.5);
  EXPECT_DOUBLE_EQ(s[1], 0.5);
  EXPECT_NEAR(s[2], 0.01, 1e-12);
}

TEST(ScanStrength, FourScansOfASymmetricHallWithSmallMarginsEach) {
  // Every pair at margin 0.02 (each alone ambiguous): a scan's three links together hold it at 0.06.
  std::vector<WeightedLink> links;
  for (std::size_t a = 0; a < 4; ++a)
    for (std::size_t b = a + 1; b < 4; ++b) links.push_back({a, b, 0.02});
  for (double s : scan_strengths(4, links, 0, 1.0)) EXPECT_GE(s, 0.06 - 1e-12);
}

}  // namespace
}  // namespace k4reg
