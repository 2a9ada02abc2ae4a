// declared_points: what a cloud file can yield, from its header alone, for every format the writers make, and
// never more than the reader then returns.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "k4reg/io/cloud_io.h"
#include "k4reg/io/declared_points.h"
#include "k4reg/util/error.h"

namespace k4reg {
namespace {

namespace fs = std::filesystem;

std::string written(const PointCloud& cloud, const std::string& extension) {
  const fs::path path = fs::temp_directory_path() / ("declared_points_test_" + std::to_string(::getpid()) + extension);
  write_cloud(path.string(), cloud);
  std::ifstream file(path, std::ios::binary);
  std::stringstream bytes;
  bytes << file.rdbuf();
  fs::remove(path);
  return bytes.str();
}

TEST(DeclaredPoints, EveryFormatDeclaresAtLeastWhatItHolds) {
  PointCloud cloud;
  for (int i = 0; i < 100; ++i) {
    cloud.points.emplace_back(float(i % 10) + 1, float(i / 10), float(i % 7));  // PTX reads (0, 0, 0) as no return
    cloud.intensity.push_back(float(i));
  }
  for (const char* extension : {".ply", ".pcd", ".xyz", ".las", ".ptx", ".e57"}) {
    const std::string bytes = written(cloud, extension);
    const std::uint64_t declared = declared_points(bytes, std::string("cloud") + extension);
    EXPECT_GE(declared, 100u) << extension;
    EXPECT_LE(declared, 120u) << extension;  // text: a line per point and a few header lines
    EXPECT_EQ(read_cloud_bytes(bytes, std::string("cloud") + extension).size(), 100u) << extension;
  }
}

TEST(DeclaredPoints, AreRefusedOverMaxPointsWhereAHeaderStatesThem) {
  const std::string ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                          "end_header\n0 0 0\n1 0 0\n0 1 0\n";
  EXPECT_EQ(declared_points(ply, "a.ply"), 3u);
  try {
    declared_points(ply, "a.ply", ReadOptions{2});
    ADD_FAILURE() << "3 points declared over a limit of 2";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kResourceExhausted);
  }
  // Text states no count: its lines, never more than the reader would hold before refusing.
  EXPECT_EQ(declared_points("0 0 0\n1 0 0\n0 1 0\n", "a.xyz"), 4u);
  EXPECT_EQ(declared_points("0 0 0\n1 0 0\n0 1 0\n", "a.xyz", ReadOptions{2}), 2u);
}

// The header pass decodes no point: a body the reader refuses still declares what its header says.
TEST(DeclaredPoints, ComeFromTheHeaderWithoutDecodingTheBody) {
  const std::string ply = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                          "property float z\nend_header\na b c\nd e f\n";
  EXPECT_EQ(declared_points(ply, "a.ply"), 2u);
  EXPECT_THROW(read_cloud_bytes(ply, "a.ply"), Error);
  const std::string pcd = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 2\nDATA ascii\na b c\nd e f\n";
  EXPECT_EQ(declared_points(pcd, "a.pcd"), 2u);
  EXPECT_THROW(read_cloud_bytes(pcd, "a.pcd"), Error);
  // A header it cannot read is refused as the reader refuses it; so is a scan selection for a one-scan format.
  EXPECT_THROW(declared_points("ply\nformat ascii 1.0\nend_header\n", "a.ply"), Error);
  ReadOptions second;
  second.scan_index = 1;
  EXPECT_THROW(declared_points(ply, "a.ply", second), Error);
}

}  // namespace
}  // namespace k4reg
