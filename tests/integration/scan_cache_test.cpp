// The pair cache's budget bounds what its scans really hold: their points and what pairs prepare on them
// afterwards (PreparedScan grows per scale), not a fixed charge per point counted once at insertion.
#include <gtest/gtest.h>

#include <random>

#include "peers/scan_cache.h"

namespace k4reg::test {
namespace {

using service::ScanCache;

// Points spread through a 2 m cube: at 2 cm nearly every point is its own voxel, so preparing a pyramid there
// holds more than the points themselves.
PointCloud random_cloud(unsigned seed, std::size_t count = 20000) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> coordinate(-1.0f, 1.0f);
  PointCloud cloud;
  for (std::size_t i = 0; i < count; ++i) cloud.points.emplace_back(coordinate(random), coordinate(random), coordinate(random));
  return cloud;
}

// What a pair registering onto the scan prepares: its voxels and its target pyramid at 2 cm.
void prepare(const ScanCache::Scan& scan) {
  IcpParams params;
  params.voxel_m = 0.02;
  scan.prepared.pyramid(0.02, params, PyramidRole::kTarget, nullptr);
}

TEST(ScanCache, CountsWhatPairsPrepareOnAScan) {
  ScanCache cache(std::size_t{1} << 30);
  std::shared_ptr<const ScanCache::Scan> scan = cache.insert("a", random_cloud(1));
  const ScanCache::Scan* held = scan.get();
  const std::size_t inserted = cache.bytes();
  EXPECT_EQ(inserted, held->bytes());
  EXPECT_GE(inserted, 12 * held->cloud.size());  // the points
  EXPECT_LT(held->prepared.bytes(), 4096u);      // nothing prepared yet

  prepare(*scan);
  EXPECT_GT(held->prepared.bytes(), 12 * held->cloud.size());  // voxels, pyramid points, normals, neighbour grids
  EXPECT_EQ(cache.bytes(), inserted);  // counted when the pair gives it back
  cache.release(std::move(scan));
  EXPECT_EQ(cache.bytes(), held->bytes());  // still held by the cache
  EXPECT_GT(cache.bytes(), inserted + 12 * held->cloud.size());
}

TEST(ScanCache, AScanPreparedPastTheBudgetLeavesOnceNoPairHoldsIt) {
  const std::size_t points_bytes = ScanCache::Scan(random_cloud(1)).bytes();
  ScanCache cache(3 * points_bytes);
  std::shared_ptr<const ScanCache::Scan> scan = cache.insert("a", random_cloud(1));
  ASSERT_EQ(cache.find("a"), scan);  // kept: it fits
  prepare(*scan);
  ASSERT_GT(scan->bytes(), 3 * points_bytes) << "the preparation must outgrow the budget for this test";

  // A pair still holds it: it stays (and is counted).
  std::shared_ptr<const ScanCache::Scan> again = cache.find("a");
  ASSERT_EQ(again, scan);
  EXPECT_GT(cache.bytes(), 3 * points_bytes);
  cache.release(std::move(again));
  EXPECT_NE(cache.find("a"), nullptr);

  // The last pair gives it back: over budget and unused, it leaves.
  cache.release(std::move(scan));
  EXPECT_EQ(cache.find("a"), nullptr);
  EXPECT_EQ(cache.bytes(), 0u);
}

TEST(ScanCache, GrowthEvictsTheLeastRecentlyUsedUnusedScan) {
  ScanCache::Scan measured(random_cloud(1));
  const std::size_t points_bytes = measured.bytes();
  prepare(measured);
  const std::size_t prepared_bytes = measured.bytes();
  // Room for both scans as they come, and for one prepared scan, not for both once one is prepared.
  const std::size_t budget = prepared_bytes + points_bytes / 2;
  ASSERT_GE(budget, 2 * points_bytes);
  ScanCache cache(budget);

  cache.release(cache.insert("a", random_cloud(1)));
  cache.release(cache.insert("b", random_cloud(2)));
  EXPECT_EQ(cache.bytes(), 2 * points_bytes);

  std::shared_ptr<const ScanCache::Scan> a = cache.find("a");  // now the most recently used
  prepare(*a);
  cache.release(std::move(a));
  EXPECT_EQ(cache.find("b"), nullptr);  // b, least recently used, made room
  EXPECT_NE(cache.find("a"), nullptr);
  EXPECT_EQ(cache.bytes(), prepared_bytes);
  EXPECT_LE(cache.bytes(), budget);
}

TEST(ScanCache, AScanAloneOverTheBudgetIsUsedButNotKept) {
  ScanCache cache(1000);
  std::shared_ptr<const ScanCache::Scan> scan = cache.insert("a", random_cloud(1));
  EXPECT_EQ(scan->cloud.size(), 20000u);
  EXPECT_EQ(cache.find("a"), nullptr);
  EXPECT_EQ(cache.bytes(), 0u);
  cache.release(std::move(scan));
  EXPECT_EQ(cache.bytes(), 0u);
}

}  // namespace
}  // namespace k4reg::test
