// The sampling a scan measures of itself: spacing and robust extent, in the cloud's own units.
#include "k4reg/geometry/sampling.h"

#include <gtest/gtest.h>

namespace k4reg {
namespace {

// A flat n x n grid of points `step` apart, plus `strays` points far out.
PointCloud grid(int n, float step, int strays = 0) {
  PointCloud cloud;
  for (int x = 0; x < n; ++x)
    for (int y = 0; y < n; ++y) cloud.points.emplace_back(x * step, y * step, 0.0f);
  for (int i = 0; i < strays; ++i) cloud.points.emplace_back(1000.0f + i, -1000.0f, 500.0f);
  return cloud;
}

TEST(Sampling, SpacingAndDiameterOfAGrid) {
  // 1 M points: measured on a subsample and scaled back to the full density.
  const Sampling s = measure_sampling(grid(1000, 0.01f));
  EXPECT_NEAR(s.spacing_m, 0.01, 0.0015);
  EXPECT_NEAR(s.diameter_m, 0.96 * 9.99 * std::sqrt(2.0), 0.2);  // 2nd..98th percentile box
  const Sampling small = measure_sampling(grid(100, 0.01f));
  EXPECT_NEAR(small.spacing_m, 0.01, 0.0005);
}

TEST(Sampling, ScalesWithTheUnitsAndIgnoresStrayReturns) {
  const Sampling metres = measure_sampling(grid(300, 0.01f));
  const Sampling millimetres = measure_sampling(grid(300, 10.0f));
  EXPECT_NEAR(millimetres.spacing_m / metres.spacing_m, 1000.0, 1.0);
  EXPECT_NEAR(millimetres.diameter_m / metres.diameter_m, 1000.0, 1.0);
  // A few hundred returns kilometres out (0.2 % of the scan) leave the extent as it was.
  const Sampling with_strays = measure_sampling(grid(300, 0.01f, 200));
  EXPECT_NEAR(with_strays.diameter_m, metres.diameter_m, 0.05 * metres.diameter_m);
}

TEST(Sampling, DegenerateCloudsGiveZero) {
  EXPECT_EQ(measure_sampling(PointCloud{}).spacing_m, 0.0);
  PointCloud one;
  one.points.emplace_back(1.0f, 2.0f, 3.0f);
  EXPECT_EQ(measure_sampling(one).diameter_m, 0.0);
}

}  // namespace
}  // namespace k4reg
