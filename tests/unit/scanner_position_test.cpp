// Where a scan's scanner stood, from the file or from the scan's own sampling: simulated stations moved into
// arbitrary frames, a real swept-profiler scan (Kurt3D, cm) moved the same way, and clouds with no single scanner.
#include "k4reg/registration/scanner_position.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <string>

#include "k4reg/geometry/sampling.h"
#include "k4reg/geometry/voxel_grid.h"
#include "k4reg/io/cloud_io.h"
#include "k4reg/registration/scanner_sampling.h"
#include "sim/scanner.h"
#include "sim/scene.h"

namespace k4reg {
namespace {

sim::SimulatedScan lab_station(int station, sim::ScanFrame frame, std::size_t points = 150000) {
  sim::ScanParams params;
  params.points = points;
  params.seed = 7;
  params.frame = frame;
  return sim::simulate_scan(sim::make_scene("lab", 0), station, params);
}

// The scanner in the scan file's frame: the station mapped back from the scene.
Eigen::Vector3d true_scanner(const sim::SimulatedScan& scan) {
  const Eigen::Matrix4d to_scan = scan.scan_to_scene.inverse();
  return to_scan.topLeftCorner<3, 3>() * scan.station_m + to_scan.topRightCorner<3, 1>();
}

ScannerPosition locate(const PointCloud& cloud) { return locate_scanner(cloud, measure_sampling(cloud).spacing_m); }

TEST(ScannerPosition, AScanInItsScannersFrameKeepsTheOriginTheSamplingConfirms) {
  const sim::SimulatedScan scan = lab_station(1, sim::ScanFrame::kScanner);
  const ScannerPosition found = locate(scan.cloud);
  EXPECT_EQ(found.source, ScannerSource::kOrigin) << found.reason;
  EXPECT_EQ(found.position_m, Eigen::Vector3d::Zero());
  EXPECT_TRUE(fits_a_scanner(found.fit)) << found.fit.share;
}

TEST(ScannerPosition, AStationInAnArbitraryFrameIsFoundFromItsSampling) {
  for (const int station : {0, 2}) {
    const sim::SimulatedScan scan = lab_station(station, sim::ScanFrame::kArbitrary);
    ASSERT_GT(scan.cloud.origin_m.norm(), 1.0);  // the scanner is not at the file's origin
    const ScannerPosition found = locate(scan.cloud);
    EXPECT_EQ(found.source, ScannerSource::kEstimated) << found.reason;
    EXPECT_LT((found.position_m - true_scanner(scan)).norm(), 0.01) << "station " << station;
    EXPECT_NEAR(found.fit.step_rad, scan.step_rad, 0.25 * scan.step_rad);
  }
}

// The neighbour search and the sampling's spacing run in parallel: the same position and fit on any thread count.
TEST(ScannerPosition, TheSameEstimateOnOneThreadAsOnMany) {
  const sim::SimulatedScan scan = lab_station(2, sim::ScanFrame::kArbitrary);
  ScannerPosition one, many;
  tbb::task_arena(1).execute([&] { one = locate(scan.cloud); });
  tbb::task_arena(4).execute([&] { many = locate(scan.cloud); });
  ASSERT_EQ(one.source, ScannerSource::kEstimated) << one.reason;
  EXPECT_EQ(one.position_m, many.position_m);
  EXPECT_EQ(one.fit.share, many.fit.share);
  EXPECT_EQ(one.fit.step_rad, many.fit.step_rad);
}

TEST(ScannerPosition, AFilesScanPoseIsTakenWhereTheSamplingAgrees) {
  sim::SimulatedScan scan = lab_station(0, sim::ScanFrame::kArbitrary);
  scan.cloud.scanner_m = true_scanner(scan);
  ScannerPosition found = locate(scan.cloud);
  EXPECT_EQ(found.source, ScannerSource::kFile) << found.reason;
  EXPECT_EQ(found.position_m, *scan.cloud.scanner_m);
  // An identity pose on a scan exported in project coordinates says the origin, which the sampling refutes.
  scan.cloud.scanner_m = Eigen::Vector3d::Zero();
  found = locate(scan.cloud);
  EXPECT_EQ(found.source, ScannerSource::kEstimated) << found.reason;
  EXPECT_LT((found.position_m - true_scanner(scan)).norm(), 0.05);
}

TEST(ScannerPosition, TwoScansMergedHaveNoSingleScanner) {
  const sim::SimulatedScan a = lab_station(0, sim::ScanFrame::kArbitrary, 100000);
  const sim::SimulatedScan b = lab_station(2, sim::ScanFrame::kArbitrary, 100000);
  std::vector<Eigen::Vector3d> merged;
  for (const sim::SimulatedScan* s : {&a, &b}) {
    // Both in the scene frame, as a registered and merged export would be.
    for (const Eigen::Vector3f& p : s->cloud.points)
      merged.push_back(s->scan_to_scene.topLeftCorner<3, 3>() * (s->cloud.origin_m + p.cast<double>()) +
                       s->scan_to_scene.topRightCorner<3, 1>() + Eigen::Vector3d(40, -25, 3));
  }
  const ScannerPosition found = locate(make_local_cloud(merged, {}));
  EXPECT_EQ(found.source, ScannerSource::kNone) << found.reason << " at " << found.position_m.transpose();
  EXPECT_FALSE(found.reason.empty());
}

TEST(ScannerPosition, AVoxelSubsampledScanHasNoScannerSampling) {
  const sim::SimulatedScan scan = lab_station(1, sim::ScanFrame::kArbitrary);
  PointCloud thinned = voxel_grid(scan.cloud, 0.05).cloud;
  thinned.origin_m = scan.cloud.origin_m;
  const ScannerPosition found = locate(thinned);
  EXPECT_EQ(found.source, ScannerSource::kNone) << found.reason << " at " << found.position_m.transpose();
}

TEST(ScannerPosition, ARealSweptProfilerScanInCentimetres) {
  // Kurt3D scan000 (3DTK): a pitching 2D scanner, 81 360 points in cm, in its scanner's frame.
  const PointCloud scan = read_cloud(std::string(K4REG_TEST_DATA_DIR) + "/kurt3d/scan000.ply");
  const ScannerPosition at_home = locate(scan);
  EXPECT_EQ(at_home.source, ScannerSource::kOrigin) << at_home.reason;
  // Moved 25 m (2500 cm) and turned, the scanner is found again from the sampling.
  std::vector<Eigen::Vector3d> moved;
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d shift(2500, -1200, 800);
  for (const Eigen::Vector3f& p : scan.points) moved.push_back(turn * (scan.origin_m + p.cast<double>()) + shift);
  const ScannerPosition found = locate(make_local_cloud(moved, {}));
  ASSERT_EQ(found.source, ScannerSource::kEstimated) << found.reason;
  EXPECT_LT((found.position_m - shift).norm(), 1.0);  // 1 cm
}

TEST(ScannerPosition, NamesOfTheSources) {
  EXPECT_STREQ(to_string(ScannerSource::kNone), "none");
  EXPECT_STREQ(to_string(ScannerSource::kOrigin), "origin");
  EXPECT_STREQ(to_string(ScannerSource::kFile), "file");
  EXPECT_STREQ(to_string(ScannerSource::kEstimated), "estimated");
}

}  // namespace
}  // namespace k4reg
