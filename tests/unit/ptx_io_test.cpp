// PTX reader and writer: hand-written files (matrix convention, zero points, colour columns), multi-scan files
// with registered poses, scan selection, round trips, malformed and hostile files; PTS with intensity and colour.
#include "k4reg/io/ptx_io.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <chrono>
#include <filesystem>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "k4reg/io/cloud_io.h"
#include "k4reg/util/error.h"
#include "io_test_support.h"

namespace k4reg {
namespace {

namespace fs = std::filesystem;
using test::expect_error;
using test::world;

class PtxIoTest : public test::TempDirTest {};

// A scan header as Cyclone writes it: position, axes, then the matrix with the translation in the last row.
std::string header(int columns, int rows, const Eigen::Matrix3d& r, const Eigen::Vector3d& t) {
  std::ostringstream s;
  s.precision(17);
  s << columns << "\n" << rows << "\n" << t.x() << " " << t.y() << " " << t.z() << "\n";
  for (int axis = 0; axis < 3; ++axis) s << r(0, axis) << " " << r(1, axis) << " " << r(2, axis) << "\n";
  for (int axis = 0; axis < 3; ++axis) s << r(0, axis) << " " << r(1, axis) << " " << r(2, axis) << " 0\n";
  s << t.x() << " " << t.y() << " " << t.z() << " 1\n";
  return s.str();
}

TEST_F(PtxIoTest, HandWrittenScanHonoursTheMatrixAndSkipsZeroPoints) {
  // Scanner rotated 90 degrees about z and standing at (500000, 5240000, 300): its x axis points along world +y.
  const Eigen::Matrix3d r = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const std::string text = header(3, 2, r, Eigen::Vector3d(500000, 5240000, 300)) +
                           "1 0 0 0.25 10 20 30\n"
                           "0 0 0 0.5 0 0 0\n"  // no return
                           "0 2 -1 0.75 1 2 3\r\n"
                           "0 0 0\n"  // no return, short form
                           "10.5 0 0 1 255 255 255\n"
                           "0 0 0 0.5 0 0 0\n";
  const std::string p = write_file("hand.ptx", text);
  EXPECT_EQ(detect_format(p), CloudFormat::kPtx);
  EXPECT_EQ(detect_format(write_file("hand.txt", text)), CloudFormat::kPtx);  // content over a text extension
  EXPECT_EQ(read_cloud(path("hand.txt")).size(), 3u);
  const PointCloud c = read_cloud(p);
  ASSERT_EQ(c.size(), 3u);
  EXPECT_LT((world(c, 0) - Eigen::Vector3d(500000, 5240001, 300)).norm(), 1e-6);
  EXPECT_LT((world(c, 1) - Eigen::Vector3d(499998, 5240000, 299)).norm(), 1e-6);
  EXPECT_LT((world(c, 2) - Eigen::Vector3d(500000, 5240010.5, 300)).norm(), 1e-6);
  ASSERT_TRUE(c.has_intensity());
  EXPECT_FLOAT_EQ(c.intensity[1], 0.75f);
}

TEST_F(PtxIoTest, SeveralScansMergeInTheCommonFrameOrOneIsSelected) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-20, 20);
  std::vector<PtxScan> scans(3);
  for (std::size_t s = 0; s < scans.size(); ++s) {
    std::vector<Eigen::Vector3d> pts;
    std::vector<float> intensity;
    for (int i = 0; i < 60; ++i) {
      pts.emplace_back(u(rng), u(rng), u(rng));
      intensity.push_back(0.01f * static_cast<float>(i) + static_cast<float>(s));
    }
    pts[7].setZero();  // a grid cell without a return
    scans[s].cloud = make_local_cloud(pts, intensity, "scan");
    scans[s].columns = 12;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = Eigen::AngleAxisd(0.7 * static_cast<double>(s) + 0.1, Eigen::Vector3d(0.2, 0.3, 1).normalized()).toRotationMatrix();
    pose.translation() = Eigen::Vector3d(512000 + 30.0 * s, 5240000 - 10.0 * s, 250 + s);
    scans[s].scanner_to_file = pose.matrix();
  }
  const std::string p = path("three.ptx");
  write_ptx(p, scans);
  auto expected = [&](std::size_t s, std::size_t i) {
    return Eigen::Vector3d((scans[s].scanner_to_file * world(scans[s].cloud, i).homogeneous()).head<3>());
  };
  const PointCloud all = read_cloud(p);
  ASSERT_EQ(all.size(), 3u * 59u);
  ASSERT_TRUE(all.has_intensity());
  double worst = 0;
  for (std::size_t s = 0, k = 0; s < 3; ++s)
    for (std::size_t i = 0; i < 60; ++i) {
      if (i == 7) continue;
      worst = std::max(worst, (world(all, k) - expected(s, i)).norm());
      EXPECT_FLOAT_EQ(all.intensity[k], scans[s].cloud.intensity[i]);
      ++k;
    }
  EXPECT_LT(worst, 2e-5);  // 6-decimal text plus float offsets

  ReadOptions second;
  second.scan_index = 1;
  const PointCloud one = read_cloud(p, second);
  ASSERT_EQ(one.size(), 59u);
  EXPECT_LT((world(one, 0) - expected(1, 0)).norm(), 2e-5);
  // A project reads each scan in its own frame, the matrix not applied.
  EXPECT_EQ(count_scans(p), 3u);
  second.apply_pose = false;
  EXPECT_LT((world(read_cloud(p, second), 0) - world(scans[1].cloud, 0)).norm(), 2e-5);
  second.apply_pose = true;
  second.scan_index = 3;
  expect_error([&] { read_cloud(p, second); }, ErrorCode::kInvalidArgument, p, "file has 3 scans");
  ReadOptions named;
  named.scan_name = "Station 1";
  expect_error([&] { read_cloud(p, named); }, ErrorCode::kInvalidArgument, p, "no names");
}

TEST_F(PtxIoTest, WriteCloudRoundTripAndIntensityRules) {
  std::vector<Eigen::Vector3d> pts = {{1.5, -2.25, 3}, {4, 5, 6.125}, {-7, 8, 9}};
  PointCloud c = make_local_cloud(pts, {0.1f, 0.2f, 0.3f}, "c");
  write_cloud(path("rt.ptx"), c);
  PointCloud r = read_cloud(path("rt.ptx"));
  ASSERT_EQ(r.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_LT((world(r, i) - pts[i]).norm(), 1e-6);
  EXPECT_FLOAT_EQ(r.intensity[2], 0.3f);
  // Without intensity the writer puts 0: a constant, read back as no intensity.
  write_cloud(path("plain.ptx"), make_local_cloud(pts, {}, "c"));
  EXPECT_FALSE(read_cloud(path("plain.ptx")).has_intensity());
  // A scan with intensity merged with one without: no intensity.
  const std::string mixed = header(1, 2, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()) + "1 2 3 0.5\n4 5 6 0.7\n" +
                            header(1, 1, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()) + "7 8 9\n\n\n";
  const PointCloud m = read_cloud(write_file("mixed.ptx", mixed));
  EXPECT_EQ(m.size(), 3u);
  EXPECT_FALSE(m.has_intensity());
}

TEST_F(PtxIoTest, PtsWithIntensityAndColourColumns) {
  // Leica PTS: a count line, then x y z intensity r g b (intensity −2048…2047); no pose.
  const std::string p = write_file("scan.pts", "2\n1.5 2.5 3.5 -1024 10 20 30\n4.5 5.5 6.5 2047 40 50 60\n");
  EXPECT_EQ(detect_format(p), CloudFormat::kXyz);  // two lines of a count and numbers: not a PTX header
  const PointCloud c = read_cloud(p);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(world(c, 1), Eigen::Vector3d(4.5, 5.5, 6.5));
  ASSERT_TRUE(c.has_intensity());
  EXPECT_FLOAT_EQ(c.intensity[0], -1024.0f);
  EXPECT_FLOAT_EQ(c.intensity[1], 2047.0f);
}

TEST_F(PtxIoTest, MalformedFilesNameTheLine) {
  const std::string h = header(2, 1, Eigen::Matrix3d::Identity(), Eigen::Vector3d(1, 2, 3));
  const struct {
    const char* name;
    std::string text;
    const char* needle;
  } cases[] = {
      {"columns.ptx", "two\n" + h.substr(2) + "1 2 3 0.5\n4 5 6 0.5\n", "column count"},
      {"matrix.ptx", h.substr(0, h.rfind("1 2 3 1")) + "1 2 3\n1 1 1 0.5\n2 2 2 0.5\n", "line 10: scan 0 header: expected a row of the 4x4 matrix"},
      {"lastcol.ptx", h.substr(0, h.find("1 0 0 0")) + "1 0 0 5\n0 1 0 0\n0 0 1 0\n1 2 3 1\n1 1 1 1\n2 2 2 2\n", "last column"},
      {"short.ptx", h + "1 2 3 0.5                     \n", "truncated: scan 0 declares 2 points, the file ends after 1"},
      {"garbage.ptx", h + "1 2 3 0.5\n4 x 6 0.5\n", "line 12: column 2 is not a number"},
      {"columns2.ptx", h + "1 2 3 0.5\n4 5 6\n", "inconsistent columns"},
      {"five.ptx", h + "1 2 3 0.5 1\n4 5 6 0.5 1\n", "3, 4 or 7 numbers"},
      {"nan.ptx", h + "1 nan 3 0.5\n4 5 6 0.5\n", "NaN"},
      {"nopoints.ptx", h + "0 0 0 0.5\n0 0 0 0.5\n", "no points"},
      {"second.ptx", h + "1 2 3 0.5\n4 5 6 0.5\n2\n", "truncated: the file ends in scan 1's header, which lacks the row count"},
      {"second2.ptx", h + "1 2 3 0.5\n4 5 6 0.5\n2\n1 1\n", "line 14: scan 1 header: expected the row count"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string p = write_file(c.name, c.text);
    expect_error([&] { read_ptx(p); }, ErrorCode::kInvalidArgument, p, c.needle);
  }
  expect_error([&] { read_ptx(write_file("empty.ptx", "")); }, ErrorCode::kInvalidArgument, "empty.ptx", "empty");
  expect_error([&] { read_ptx(write_file("blank.ptx", "\n \n")); }, ErrorCode::kInvalidArgument, "blank.ptx", "no scans");
}

TEST_F(PtxIoTest, HugeGridClaimsAreRefusedInstantlyAndMaxPointsHolds) {
  const std::string p = write_file(
      "huge.ptx", "1000000\n1000000\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n1 2 3 0.5\n");
  const auto t0 = std::chrono::steady_clock::now();
  expect_error([&] { read_cloud(p); }, ErrorCode::kInvalidArgument, p, "truncated");
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::milliseconds(100));
  const std::string overflow = write_file(
      "overflow.ptx",
      "18446744073709551615\n18446744073709551615\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n1 2 3\n");
  expect_error([&] { read_cloud(overflow); }, ErrorCode::kInvalidArgument, overflow, "truncated");

  std::vector<PtxScan> scans(1);
  scans[0].cloud = make_local_cloud({{1, 2, 3}, {4, 5, 6}, {7, 8, 9}}, {}, "c");
  write_ptx(path("three.ptx"), scans);
  ReadOptions limited;
  limited.max_points = 2;
  expect_error([&] { read_cloud(path("three.ptx"), limited); }, ErrorCode::kResourceExhausted, "three.ptx", "more than 2");
  expect_error([&] { write_ptx(path("grid.ptx"), {PtxScan{scans[0].cloud, Eigen::Matrix4d::Identity(), 2}}); },
               ErrorCode::kInvalidArgument, "grid.ptx", "grid of 2 columns");
}

}  // namespace
}  // namespace k4reg
