// Point-cloud file I/O: round trips of every writer, hand-written files, malformed input, real scans.
#include <gtest/gtest.h>
#include <stdlib.h>
#include <unistd.h>

#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "k4reg/io/cloud_io.h"
#include "k4reg/util/error.h"
#include "k4reg/io/gt_pairs.h"
#include "k4reg/io/pcd_io.h"
#include "k4reg/io/ply_io.h"
#include "k4reg/io/xyz_io.h"

namespace k4reg {
namespace {

namespace fs = std::filesystem;

const std::string kData = K4REG_TEST_DATA_DIR;

class CloudIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string tmpl = (fs::temp_directory_path() / "k4reg_cloud_io_XXXXXX").string();
    ASSERT_NE(::mkdtemp(tmpl.data()), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string path(const std::string& name) const { return (fs::path(dir_) / name).string(); }
  std::string write_file(const std::string& name, const std::string& bytes) const {
    const std::string p = path(name);
    std::ofstream out(p, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return p;
  }
  std::string dir_;
};

// Runs fn, expects a k4reg::Error with `code` whose message names the file and contains `needle`.
void expect_error(const std::function<void()>& fn, ErrorCode code, const std::string& file,
                  const std::string& needle = "") {
  try {
    fn();
    ADD_FAILURE() << "no error thrown for " << file;
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_EQ(e.code(), code) << msg;
    EXPECT_NE(msg.find(fs::path(file).filename().string()), std::string::npos) << "message lacks file name: " << msg;
    if (!needle.empty()) {
      EXPECT_NE(msg.find(needle), std::string::npos) << "message lacks '" << needle << "': " << msg;
    }
  } catch (const std::exception& e) {
    ADD_FAILURE() << "wrong exception type: " << e.what();
  }
}

Eigen::Vector3d world(const PointCloud& c, std::size_t i) { return c.origin_m + c.points[i].cast<double>(); }

PointCloud small_cloud(bool utm, bool with_intensity) {
  std::vector<Eigen::Vector3d> pts;
  std::vector<float> intensity;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-20.0, 20.0);
  const Eigen::Vector3d base = utm ? Eigen::Vector3d(500000.123, 5240000.456, 312.789) : Eigen::Vector3d::Zero();
  pts.push_back(base);
  for (int i = 0; i < 200; ++i) pts.push_back(base + Eigen::Vector3d(u(rng), u(rng), 0.1 * u(rng)));
  if (with_intensity)
    for (std::size_t i = 0; i < pts.size(); ++i) intensity.push_back(static_cast<float>(i) * 0.37f - 3.0f);
  PointCloud c = make_local_cloud(pts, intensity, "test");
  EXPECT_EQ(!c.origin_m.isZero(), utm);
  return c;
}

void expect_same(const PointCloud& a, const PointCloud& b, double tol) {
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.has_intensity(), b.has_intensity());
  double worst = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    worst = std::max(worst, (world(a, i) - world(b, i)).cwiseAbs().maxCoeff());
    if (a.has_intensity()) {
      ASSERT_FLOAT_EQ(a.intensity[i], b.intensity[i]) << i;
    }
  }
  EXPECT_LE(worst, tol);
}

// ------------------------------------------------------------------------------------------------
// Round trips
// ------------------------------------------------------------------------------------------------

TEST_F(CloudIoTest, PlyRoundTripEveryEncoding) {
  for (PlyEncoding enc : {PlyEncoding::kAscii, PlyEncoding::kBinaryLittleEndian, PlyEncoding::kBinaryBigEndian}) {
    for (bool utm : {false, true}) {
      for (bool with_i : {false, true}) {
        SCOPED_TRACE(::testing::Message() << "enc " << static_cast<int>(enc) << " utm " << utm << " i " << with_i);
        const PointCloud c = small_cloud(utm, with_i);
        const std::string p = path("rt.ply");
        write_ply(p, c, enc);
        const PointCloud r = read_ply(p);
        // float32 near the origin is exact; float64 at UTM is exact up to the float offsets.
        expect_same(c, r, utm ? 1e-6 : 0.0);
        if (utm) {
          EXPECT_LT((world(r, 0) - Eigen::Vector3d(500000.123, 5240000.456, 312.789)).norm(), 1e-3);
        }
        EXPECT_EQ(read_cloud(p).size(), c.size());
      }
    }
  }
}

TEST_F(CloudIoTest, PcdRoundTripEveryEncoding) {
  for (PcdEncoding enc : {PcdEncoding::kAscii, PcdEncoding::kBinary, PcdEncoding::kBinaryCompressed}) {
    for (bool utm : {false, true}) {
      for (bool with_i : {false, true}) {
        SCOPED_TRACE(::testing::Message() << "enc " << static_cast<int>(enc) << " utm " << utm << " i " << with_i);
        const PointCloud c = small_cloud(utm, with_i);
        const std::string p = path("rt.pcd");
        write_pcd(p, c, enc);
        const PointCloud r = read_pcd(p);
        expect_same(c, r, utm ? 1e-6 : 0.0);
        if (utm) {
          EXPECT_LT((world(r, 0) - Eigen::Vector3d(500000.123, 5240000.456, 312.789)).norm(), 1e-3);
        }
        EXPECT_EQ(read_cloud(p).size(), c.size());
      }
    }
  }
}

TEST_F(CloudIoTest, XyzRoundTripEveryStyle) {
  struct Case {
    XyzStyle style;
    const char* name;
  };
  for (const Case& k : {Case{XyzStyle::kSpace, "rt.xyz"}, Case{XyzStyle::kComma, "rt.csv"}, Case{XyzStyle::kPtsCount, "rt.pts"}}) {
    for (bool utm : {false, true}) {
      for (bool with_i : {false, true}) {
        SCOPED_TRACE(::testing::Message() << k.name << " utm " << utm << " i " << with_i);
        const PointCloud c = small_cloud(utm, with_i);
        const std::string p = path(k.name);
        write_xyz(p, c, k.style);
        const PointCloud r = read_xyz(p);
        expect_same(c, r, utm ? 1e-6 : 0.0);  // 6 decimals at UTM, exact shortest floats near the origin
        EXPECT_EQ(read_cloud(p).size(), c.size());
      }
    }
  }
}

// 3DTK's .3d scans (the Kurt3D robot's): a first line with the sweep size, then x y z per line. The size line
// is skipped only first; later, or with another word than "x", it is an error naming the line.
TEST_F(CloudIoTest, ThreeDtkScanSkipsItsSweepSizeLine) {
  const PointCloud c = read_cloud(write_file("scan000.3d", "360 x 225\n10.1 0 0\n10.0996 -0.0662149 0.0581712\n1 2 3\n"));
  ASSERT_EQ(c.size(), 3u);
  EXPECT_NEAR(c.points[1].x() + c.origin_m.x(), 10.0996, 1e-5);
  EXPECT_FALSE(c.has_intensity());
  expect_error([&] { read_cloud(write_file("late.3d", "1 2 3\n360 x 225\n")); }, ErrorCode::kInvalidArgument, "late.3d", "line 2");
  expect_error([&] { read_cloud(write_file("by.3d", "360 by 225\n1 2 3\n")); }, ErrorCode::kInvalidArgument, "by.3d", "line 1");
}

TEST_F(CloudIoTest, WriteCloudPicksFormatFromExtension) {
  const PointCloud c = small_cloud(true, true);
  const std::pair<const char*, CloudFormat> cases[] = {
      {"a.ply", CloudFormat::kPly}, {"a.PLY", CloudFormat::kPly}, {"a.pcd", CloudFormat::kPcd},
      {"a.xyz", CloudFormat::kXyz}, {"a.txt", CloudFormat::kXyz}, {"a.pts", CloudFormat::kXyz},
      {"a.csv", CloudFormat::kXyz}};
  for (const auto& [name, format] : cases) {
    SCOPED_TRACE(name);
    const std::string p = path(name);
    write_cloud(p, c);
    EXPECT_EQ(detect_format(p), format);
    expect_same(c, read_cloud(p), 1e-6);
  }
  // .ply is binary little-endian, .pcd binary.
  std::ifstream ply(path("a.ply"));
  std::string line;
  std::getline(ply, line);
  std::getline(ply, line);
  EXPECT_EQ(line, "format binary_little_endian 1.0");
  std::ifstream pcd(path("a.pcd"));
  std::string all((std::istreambuf_iterator<char>(pcd)), std::istreambuf_iterator<char>());
  EXPECT_NE(all.find("\nDATA binary\n"), std::string::npos);
  EXPECT_NE(all.find("SIZE 8 8 8 4"), std::string::npos);  // double coordinates at UTM
  // No temporary files are left behind.
  std::size_t files = 0;
  for (const auto& entry : fs::directory_iterator(dir_)) files += entry.is_regular_file();
  EXPECT_EQ(files, std::size(cases));
  expect_error([&] { write_cloud(path("a.obj"), c); }, ErrorCode::kInvalidArgument, "a.obj", "extension");
  expect_error([&] { write_cloud(path("nodir/a.ply"), c); }, ErrorCode::kNotFound, "a.ply");
}

TEST_F(CloudIoTest, DetectFormatByContentWithExtensionHint) {
  const PointCloud c = small_cloud(false, false);
  write_ply(path("cloud.xyz"), c, PlyEncoding::kAscii);  // content wins over a misleading extension
  EXPECT_EQ(detect_format(path("cloud.xyz")), CloudFormat::kPly);
  EXPECT_EQ(read_cloud(path("cloud.xyz")).size(), c.size());
  write_pcd(path("cloud"), c, PcdEncoding::kBinary);  // no extension
  EXPECT_EQ(detect_format(path("cloud")), CloudFormat::kPcd);
  write_file("numbers", "1 2 3\n4 5 6\n");
  EXPECT_EQ(detect_format(path("numbers")), CloudFormat::kXyz);
  write_file("headerless.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nPOINTS 1\nDATA ascii\n1 2 3\n");
  EXPECT_EQ(detect_format(path("headerless.pcd")), CloudFormat::kPcd);
  EXPECT_EQ(read_cloud(path("headerless.pcd")).size(), 1u);
  write_file("blob.bin", std::string("\x01\x02\x03\x00\xff", 5));
  expect_error([&] { detect_format(path("blob.bin")); }, ErrorCode::kInvalidArgument, "blob.bin", "format");
  expect_error([&] { detect_format(path("missing.ply")); }, ErrorCode::kNotFound, "missing.ply");
}

TEST_F(CloudIoTest, ReadFromBytesInMemory) {
  const PointCloud c = small_cloud(true, true);
  write_cloud(path("mem.ply"), c);
  std::ifstream in(path("mem.ply"), std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  expect_same(c, read_cloud_bytes(bytes, "upload.bin"), 1e-6);
  expect_same(c, read_ply_bytes(bytes, "upload.ply"), 1e-6);
  expect_error([&] { read_cloud_bytes(bytes.substr(0, bytes.size() - 3), "upload.ply"); }, ErrorCode::kInvalidArgument,
               "upload.ply", "truncated");
}

TEST(LzfTest, RoundTripsAndRejectsCorruptInput) {
  std::mt19937 rng(3);
  std::vector<std::string> inputs = {"", "a", "abc", "abcabcabcabcabcabcabcabc", std::string(100000, '\0'),
                                     std::string(1000, 'x') + "y" + std::string(70000, 'x')};
  std::string random(200000, '\0');
  for (char& ch : random) ch = static_cast<char>(rng() & 0xff);
  inputs.push_back(random);
  std::string floats;
  for (int i = 0; i < 50000; ++i) {
    const float v = 100.0f + 0.01f * static_cast<float>(i % 977);
    floats.append(reinterpret_cast<const char*>(&v), 4);
  }
  inputs.push_back(floats);
  for (const std::string& in : inputs) {
    const std::string packed = lzf_compress(in);
    EXPECT_EQ(lzf_decompress(packed, in.size(), "x.pcd"), in) << in.size();
    if (in.size() > 10000 && in != random) {
      EXPECT_LT(packed.size(), in.size() / 2);
    }
  }
  const std::string packed = lzf_compress(inputs[3]);
  expect_error([&] { lzf_decompress(packed, inputs[3].size() + 5, "x.pcd"); }, ErrorCode::kInvalidArgument, "x.pcd",
               "corrupt");
  expect_error([&] { lzf_decompress(std::string("\xe0\xff\x10", 3), 300, "x.pcd"); }, ErrorCode::kInvalidArgument,
               "x.pcd", "before the start");
  expect_error([&] { lzf_decompress(std::string("\x05" "ab", 3), 6, "x.pcd"); }, ErrorCode::kInvalidArgument, "x.pcd",
               "past the end");
}

// ------------------------------------------------------------------------------------------------
// Hand-written files
// ------------------------------------------------------------------------------------------------

// Byte builders for binary PLY/PCD bodies.
template <typename T>
void put(std::string& out, T value, bool big_endian = false) {
  char b[sizeof(T)];
  std::memcpy(b, &value, sizeof(T));
  if (big_endian == (std::endian::native == std::endian::little))
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
  out.append(b, sizeof(T));
}

TEST_F(CloudIoTest, PlyAsciiMixedTypesListsAndScalarIntensity) {
  const std::string p = write_file("mixed.ply",
                                   "ply\r\n"
                                   "format ascii 1.0\n"
                                   "comment hand written\n"
                                   "obj_info scanner test\n"
                                   "element camera 1\n"
                                   "property float view_px\n"
                                   "element face 2\n"
                                   "property list uchar int vertex_indices\n"
                                   "element vertex 3\n"
                                   "property uchar red\n"
                                   "property short x\n"
                                   "property double y\n"
                                   "property list uint8 int32 neighbours\n"
                                   "property float64 z\n"
                                   "property float scalar_Intensity\n"
                                   "element range_grid 4\n"
                                   "property list uchar int vertex_indices\n"
                                   "end_header\n"
                                   "0.5\n"
                                   "3 0 1 2\n"
                                   "0\n"
                                   "255 -12 1.5 2 7 8 1e3 0.25\n"
                                   "0   7  -2.25 0 4.5 100\n"
                                   "9 0 0 1 5 -1 7\n"
                                   "1 0\n0\n1 2\n1 1\n");
  const PointCloud c = read_ply(p);
  ASSERT_EQ(c.size(), 3u);
  ASSERT_TRUE(c.has_intensity());
  EXPECT_EQ(world(c, 0), Eigen::Vector3d(-12, 1.5, 1000));
  EXPECT_EQ(world(c, 1), Eigen::Vector3d(7, -2.25, 4.5));
  EXPECT_EQ(world(c, 2), Eigen::Vector3d(0, 0, -1));
  EXPECT_FLOAT_EQ(c.intensity[0], 0.25f);
  EXPECT_FLOAT_EQ(c.intensity[1], 100.0f);
  EXPECT_FLOAT_EQ(c.intensity[2], 7.0f);
}

std::string binary_ply_with_lists(bool big_endian) {
  std::string s = std::string("ply\nformat ") + (big_endian ? "binary_big_endian" : "binary_little_endian") +
                  " 1.0\n"
                  "element face 2\n"
                  "property list uchar int vertex_indices\n"
                  "property uint16 flags\n"
                  "element vertex 2\n"
                  "property char tag\n"
                  "property float x\n"
                  "property double y\n"
                  "property int z\n"
                  "property ushort reflectance\n"
                  "property uint extra\n"
                  "element range_grid 3\n"
                  "property list int uint vertex_indices\n"
                  "end_header\n";
  // face 0: 3 indices, face 1: 0 indices
  put<std::uint8_t>(s, 3);
  put<std::int32_t>(s, 0, big_endian);
  put<std::int32_t>(s, 1, big_endian);
  put<std::int32_t>(s, 2, big_endian);
  put<std::uint16_t>(s, 9, big_endian);
  put<std::uint8_t>(s, 0);
  put<std::uint16_t>(s, 10, big_endian);
  // vertices
  put<std::int8_t>(s, -1);
  put<float>(s, 1.5f, big_endian);
  put<double>(s, -2.25, big_endian);
  put<std::int32_t>(s, 100000, big_endian);
  put<std::uint16_t>(s, 65000, big_endian);
  put<std::uint32_t>(s, 4000000000u, big_endian);
  put<std::int8_t>(s, 2);
  put<float>(s, -0.5f, big_endian);
  put<double>(s, 8.0, big_endian);
  put<std::int32_t>(s, -3, big_endian);
  put<std::uint16_t>(s, 17, big_endian);
  put<std::uint32_t>(s, 1u, big_endian);
  // range_grid (after the vertex element; never needed)
  put<std::int32_t>(s, 1, big_endian);
  put<std::uint32_t>(s, 0, big_endian);
  put<std::int32_t>(s, 0, big_endian);
  put<std::int32_t>(s, 0, big_endian);
  return s;
}

TEST_F(CloudIoTest, PlyBinaryBothByteOrdersWithListElementsAroundVertex) {
  for (bool big_endian : {false, true}) {
    SCOPED_TRACE(big_endian);
    const std::string p = write_file(big_endian ? "be.ply" : "le.ply", binary_ply_with_lists(big_endian));
    const PointCloud c = read_cloud(p);
    ASSERT_EQ(c.size(), 2u);
    EXPECT_EQ(world(c, 0), Eigen::Vector3d(1.5, -2.25, 100000));
    EXPECT_EQ(world(c, 1), Eigen::Vector3d(-0.5, 8.0, -3));
    ASSERT_TRUE(c.has_intensity());
    EXPECT_FLOAT_EQ(c.intensity[0], 65000.0f);
    EXPECT_FLOAT_EQ(c.intensity[1], 17.0f);
  }
}

TEST_F(CloudIoTest, PlyIntensityNamePriority) {
  const std::string p = write_file("names.ply",
                                   "ply\nformat ascii 1.0\nelement vertex 1\n"
                                   "property float x\nproperty float y\nproperty float z\n"
                                   "property float i\nproperty float reflectance\nproperty float scalar_Intensity\n"
                                   "end_header\n1 2 3 4 5 6\n");
  EXPECT_FLOAT_EQ(read_ply(p).intensity[0], 6.0f);  // scalar_Intensity ranks before reflectance and i
}

TEST_F(CloudIoTest, PcdAsciiExtraFieldsAndCountAboveOne) {
  const std::string p = write_file("extra.pcd",
                                   "# .PCD v0.7 - Point Cloud Data file format\n"
                                   "VERSION 0.7\n"
                                   "FIELDS normal_x x hist y z rgb intensity\n"
                                   "SIZE 4 4 4 8 4 4 2\n"
                                   "TYPE F F F F F U U\n"
                                   "COUNT 1 1 3 1 1 1 1\n"
                                   "WIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n"
                                   "0.1 1 7 8 9 2 3 4278190080 12\n"
                                   "0.2 -1 0 0 0 -2 -3.5 0 65535\n");
  const PointCloud c = read_pcd(p);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(world(c, 0), Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(world(c, 1), Eigen::Vector3d(-1, -2, -3.5));
  ASSERT_TRUE(c.has_intensity());
  EXPECT_FLOAT_EQ(c.intensity[1], 65535.0f);
}

// PDAL names the coordinates X Y Z.
TEST_F(CloudIoTest, PcdUpperCaseCoordinateFieldsAndOneScanPerFile) {
  const std::string p = write_file("pdal.pcd",
                                   "VERSION 0.7\nFIELDS X Y Z Intensity\nSIZE 8 8 8 2\nTYPE F F F U\nCOUNT 1 1 1 1\n"
                                   "WIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n"
                                   "512000.5 5240000.25 300 7\n512001 5240001 301 9\n");
  const PointCloud c = read_cloud(p);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(world(c, 1), Eigen::Vector3d(512001, 5240001, 301));
  EXPECT_FLOAT_EQ(c.intensity[0], 7.0f);
  EXPECT_EQ(count_scans(p), 1u);
}

std::string binary_pcd_organised(bool compressed) {
  // Organised 3 x 2 cloud; fields: x y z (F4), padding "_" (U1 x 3), normal (F4 x 3), intensity (U1),
  // d (F8). Points 1 and 4 are invalid (NaN), as PCL writes them.
  const float nan = std::numeric_limits<float>::quiet_NaN();
  struct P {
    float x, y, z;
    std::uint8_t i;
  };
  const P pts[6] = {{1, 2, 3, 10}, {nan, nan, nan, 0}, {4, 5, 6, 20}, {7, 8, 9, 30}, {0, nan, 0, 0}, {-1, -2, -3, 40}};
  std::string header =
      "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z _ normal intensity d\nSIZE 4 4 4 1 4 1 8\nTYPE F F F U F U F\n"
      "COUNT 1 1 1 3 3 1 1\nWIDTH 3\nHEIGHT 2\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 6\n";
  std::string body;
  if (!compressed) {
    for (const P& p : pts) {
      put(body, p.x);
      put(body, p.y);
      put(body, p.z);
      body.append(3, '\x7f');
      for (int k = 0; k < 3; ++k) put(body, 0.5f);
      put(body, p.i);
      put(body, 1.0e300);
    }
    return header + "DATA binary\n" + body;
  }
  std::string columns;
  for (const P& p : pts) put(columns, p.x);
  for (const P& p : pts) put(columns, p.y);
  for (const P& p : pts) put(columns, p.z);
  for (int i = 0; i < 6; ++i) columns.append(3, '\x7f');
  for (int i = 0; i < 6 * 3; ++i) put(columns, 0.5f);
  for (const P& p : pts) put(columns, p.i);
  for (int i = 0; i < 6; ++i) put(columns, 1.0e300);
  const std::string packed = lzf_compress(columns);
  put(body, static_cast<std::uint32_t>(packed.size()));
  put(body, static_cast<std::uint32_t>(columns.size()));
  return header + "DATA binary_compressed\n" + body + packed;
}

TEST_F(CloudIoTest, PcdOrganisedCloudSkipsNanPoints) {
  for (bool compressed : {false, true}) {
    SCOPED_TRACE(compressed);
    const std::string p = write_file("organised.pcd", binary_pcd_organised(compressed));
    const PointCloud c = read_cloud(p);
    ASSERT_EQ(c.size(), 4u);
    EXPECT_EQ(world(c, 0), Eigen::Vector3d(1, 2, 3));
    EXPECT_EQ(world(c, 1), Eigen::Vector3d(4, 5, 6));
    EXPECT_EQ(world(c, 3), Eigen::Vector3d(-1, -2, -3));
    ASSERT_TRUE(c.has_intensity());
    EXPECT_FLOAT_EQ(c.intensity[2], 30.0f);
    EXPECT_FLOAT_EQ(c.intensity[3], 40.0f);
  }
  // All points invalid → no points.
  const std::string all_nan = write_file(
      "allnan.pcd", "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\nnan nan nan\nnan nan nan\n");
  expect_error([&] { read_pcd(all_nan); }, ErrorCode::kInvalidArgument, all_nan, "no points");
  // Infinity is not PCL's invalid marker: refused.
  const std::string inf = write_file(
      "inf.pcd", "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n1 2 3\n1 inf 3\n");
  expect_error([&] { read_pcd(inf); }, ErrorCode::kInvalidArgument, inf, "point 1");
}

TEST_F(CloudIoTest, PtsWithCountLineAndCsvWithHeader) {
  const std::string pts = write_file("scan.pts",
                                     "3\n"
                                     "10.5 20.25 -1 -1200 10 20 30\n"
                                     "11.5 21.25 -2 -1100 10 20 30\r\n"
                                     "12.5 22.25 -3 -1000 10 20 30\n"
                                     "1\n"
                                     "13.5 23.25 -4 -900 1 2 3\n");
  const PointCloud a = read_cloud(pts);
  ASSERT_EQ(a.size(), 4u);
  EXPECT_EQ(world(a, 3), Eigen::Vector3d(13.5, 23.25, -4));
  ASSERT_TRUE(a.has_intensity());
  EXPECT_FLOAT_EQ(a.intensity[0], -1200.0f);

  const std::string csv = write_file("scan.csv",
                                     "# exported\n"
                                     "X,Y,Z\n"
                                     "// comment\n"
                                     "\n"
                                     "500000.125,5240000.5,100.25\n"
                                     "500001.125, 5240001.5, +101.25\n"
                                     "  500002.125 ,5240002.5 ,1.0225e2\n");
  const PointCloud b = read_cloud(csv);
  ASSERT_EQ(b.size(), 3u);
  EXPECT_FALSE(b.has_intensity());
  EXPECT_FALSE(b.origin_m.isZero());
  EXPECT_LT((world(b, 2) - Eigen::Vector3d(500002.125, 5240002.5, 102.25)).norm(), 1e-6);
}

// ------------------------------------------------------------------------------------------------
// Malformed input
// ------------------------------------------------------------------------------------------------

TEST_F(CloudIoTest, MissingFileIsNotFound) {
  for (const char* name : {"nope.ply", "nope.pcd", "nope.xyz", "nope"}) {
    const std::string p = path(name);
    expect_error([&] { read_cloud(p); }, ErrorCode::kNotFound, p, "no such file");
  }
  expect_error([&] { read_ply(path("nope.ply")); }, ErrorCode::kNotFound, "nope.ply");
  expect_error([&] { read_pcd(path("nope.pcd")); }, ErrorCode::kNotFound, "nope.pcd");
  expect_error([&] { read_xyz(path("nope.xyz")); }, ErrorCode::kNotFound, "nope.xyz");
  expect_error([&] { read_gt_pairs(path("nope.log")); }, ErrorCode::kNotFound, "nope.log");
  expect_error([&] { read_cloud(dir_); }, ErrorCode::kInvalidArgument, dir_, "directory");
}

TEST_F(CloudIoTest, EmptyFiles) {
  for (const char* name : {"empty.ply", "empty.pcd", "empty.xyz", "empty"}) {
    const std::string p = write_file(name, "");
    expect_error([&] { read_cloud(p); }, ErrorCode::kInvalidArgument, p, "empty file");
  }
  expect_error([&] { read_ply(path("empty.ply")); }, ErrorCode::kInvalidArgument, "empty.ply", "empty file");
  expect_error([&] { read_pcd(path("empty.pcd")); }, ErrorCode::kInvalidArgument, "empty.pcd", "empty file");
  const std::string comments = write_file("comments.xyz", "# nothing here\n\n// really\n");
  expect_error([&] { read_cloud(comments); }, ErrorCode::kInvalidArgument, comments, "no points");
  const std::string zero = write_file("zero.ply", "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\n"
                                                  "property float y\nproperty float z\nend_header\n");
  expect_error([&] { read_cloud(zero); }, ErrorCode::kInvalidArgument, zero, "no points");
  const std::string zero_pcd = write_file("zero.pcd", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 0\n"
                                                      "HEIGHT 1\nPOINTS 0\nDATA binary\n");
  expect_error([&] { read_cloud(zero_pcd); }, ErrorCode::kInvalidArgument, zero_pcd, "no points");
}

TEST_F(CloudIoTest, WrongMagicAndBadHeaders) {
  const std::string magic = write_file("magic.ply", "plx\nformat ascii 1.0\nend_header\n");
  expect_error([&] { read_cloud(magic); }, ErrorCode::kInvalidArgument, magic, "wrong magic");
  const std::string pcd = write_file("magic.pcd", "hello world\n");
  expect_error([&] { read_cloud(pcd); }, ErrorCode::kInvalidArgument, pcd, "not a PCD file");
  const std::string no_end = write_file("noend.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n");
  expect_error([&] { read_cloud(no_end); }, ErrorCode::kInvalidArgument, no_end, "end_header");
  const std::string no_z = write_file("noz.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                                                 "property float y\nproperty float nz\nend_header\n1 2 3\n");
  expect_error([&] { read_cloud(no_z); }, ErrorCode::kInvalidArgument, no_z, "'z'");
  const std::string no_vertex = write_file("novertex.ply", "ply\nformat ascii 1.0\nelement face 1\n"
                                                           "property list uchar int vertex_indices\nend_header\n0\n");
  expect_error([&] { read_cloud(no_vertex); }, ErrorCode::kInvalidArgument, no_vertex, "vertex");
  const std::string bad_type = write_file("badtype.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\n"
                                                         "end_header\n");
  expect_error([&] { read_cloud(bad_type); }, ErrorCode::kInvalidArgument, bad_type, "line 4");
  const std::string bad_format = write_file("badformat.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n");
  expect_error([&] { read_cloud(bad_format); }, ErrorCode::kInvalidArgument, bad_format,
               "header line 2: unknown PLY format");
  const std::string negative = write_file("negative.ply", "ply\nformat ascii 1.0\nelement vertex -5\nend_header\n");
  expect_error([&] { read_cloud(negative); }, ErrorCode::kInvalidArgument, negative,
               "header line 3: the element count is not a non-negative integer");
  const std::string pcd_no_y = write_file("noy.pcd", "VERSION 0.7\nFIELDS x z\nSIZE 4 4\nTYPE F F\nWIDTH 1\nHEIGHT 1\n"
                                                     "POINTS 1\nDATA ascii\n1 2\n");
  expect_error([&] { read_cloud(pcd_no_y); }, ErrorCode::kInvalidArgument, pcd_no_y, "'y'");
  const std::string pcd_sizes = write_file("sizes.pcd", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4\nTYPE F F F\nWIDTH 1\n"
                                                        "HEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 3\n");
  expect_error([&] { read_cloud(pcd_sizes); }, ErrorCode::kInvalidArgument, pcd_sizes, "SIZE");
  const std::string pcd_no_data = write_file("nodata.pcd", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\n");
  expect_error([&] { read_cloud(pcd_no_data); }, ErrorCode::kInvalidArgument, pcd_no_data, "DATA");
  const std::string pcd_points = write_file("points.pcd", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\n"
                                                          "HEIGHT 2\nPOINTS 3\nDATA ascii\n");
  expect_error([&] { read_cloud(pcd_points); }, ErrorCode::kInvalidArgument, pcd_points, "POINTS");
}

TEST_F(CloudIoTest, TruncatedBodies) {
  const PointCloud c = small_cloud(false, true);
  // Binary PLY.
  write_ply(path("full.ply"), c, PlyEncoding::kBinaryLittleEndian);
  std::ifstream in(path("full.ply"), std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string ply = write_file("cut.ply", bytes.substr(0, bytes.size() - 7));
  expect_error([&] { read_cloud(ply); }, ErrorCode::kInvalidArgument, ply, "truncated: header says 201 vertices, data holds 200");
  // Binary list element before the vertex element, cut inside it.
  const std::string lists = binary_ply_with_lists(true);
  const std::string ply_list = write_file("cutlist.ply", lists.substr(0, lists.find("end_header\n") + 11 + 9));
  expect_error([&] { read_cloud(ply_list); }, ErrorCode::kInvalidArgument, ply_list, "truncated");
  // ASCII PLY.
  write_ply(path("full_a.ply"), c, PlyEncoding::kAscii);
  std::ifstream in_a(path("full_a.ply"), std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in_a)), std::istreambuf_iterator<char>());
  const std::string ply_a = write_file("cut_a.ply", text.substr(0, text.size() * 2 / 3));
  expect_error([&] { read_cloud(ply_a); }, ErrorCode::kInvalidArgument, ply_a, "truncated");
  // PCD binary, compressed, ascii.
  for (PcdEncoding enc : {PcdEncoding::kBinary, PcdEncoding::kBinaryCompressed, PcdEncoding::kAscii}) {
    write_pcd(path("full.pcd"), c, enc);
    std::ifstream in_p(path("full.pcd"), std::ios::binary);
    std::string pb((std::istreambuf_iterator<char>(in_p)), std::istreambuf_iterator<char>());
    const std::string pcd = write_file("cut.pcd", pb.substr(0, pb.size() - pb.size() / 4));
    expect_error([&] { read_cloud(pcd); }, ErrorCode::kInvalidArgument, pcd, "truncated");
  }
}

TEST_F(CloudIoTest, HugeHeaderCountsAreRefusedInstantly) {
  const std::string xyz_props = "property float x\nproperty float y\nproperty float z\n";
  std::vector<std::string> files;
  files.push_back(write_file("huge_b.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\n" +
                                               xyz_props + "end_header\n" + std::string(16, '\0')));
  files.push_back(write_file("huge_a.ply", "ply\nformat ascii 1.0\nelement vertex 1000000000000\n" + xyz_props +
                                               "end_header\n1 2 3\n"));
  files.push_back(write_file("huge_face.ply", "ply\nformat binary_little_endian 1.0\nelement face 1000000000000\n"
                                              "property list uchar int vertex_indices\nelement vertex 1\n" +
                                                  xyz_props + "end_header\n" + std::string(16, '\0')));
  files.push_back(write_file("huge_face_a.ply", "ply\nformat ascii 1.0\nelement face 1000000000000\n"
                                                "property list uchar int vertex_indices\nelement vertex 1\n" +
                                                    xyz_props + "end_header\n0\n0\n"));
  const std::string pcd_head = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1000000000000\nHEIGHT 1\n"
                               "POINTS 1000000000000\n";
  files.push_back(write_file("huge_b.pcd", pcd_head + "DATA binary\n" + std::string(12, '\0')));
  files.push_back(write_file("huge_a.pcd", pcd_head + "DATA ascii\n1 2 3\n"));
  // binary_compressed whose declared uncompressed size (4 GB - 4) cannot come from 8 bytes of LZF.
  std::string small_head = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 357913941\nHEIGHT 1\nDATA binary_compressed\n";
  std::string sizes;
  put<std::uint32_t>(sizes, 8);
  put<std::uint32_t>(sizes, 357913941u * 12u);
  files.push_back(write_file("huge_c.pcd", small_head + sizes + std::string(8, '\0')));
  for (const std::string& f : files) {
    SCOPED_TRACE(f);
    EXPECT_LT(fs::file_size(f), 200u);
    const auto t0 = std::chrono::steady_clock::now();
    expect_error([&] { read_cloud(f); }, ErrorCode::kInvalidArgument, f, "truncated");
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_LT(ms, 100.0);
  }
}

TEST_F(CloudIoTest, NanAndInfCoordinatesNameThePoint) {
  const std::string head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                           "property float z\nend_header\n";
  const std::string a = write_file("nan_a.ply", head + "1 2 3\n4 nan 6\n7 8 9\n");
  expect_error([&] { read_cloud(a); }, ErrorCode::kInvalidArgument, a, "point 1");
  const std::string b = write_file("inf_a.ply", head + "1 2 3\n4 5 6\n7 8 -inf\n");
  expect_error([&] { read_cloud(b); }, ErrorCode::kInvalidArgument, b, "point 2");
  std::string bin = "ply\nformat binary_big_endian 1.0\nelement vertex 2\nproperty double x\nproperty double y\n"
                    "property double z\nend_header\n";
  for (double v : {1.0, 2.0, 3.0, 4.0, std::numeric_limits<double>::quiet_NaN(), 6.0}) put(bin, v, true);
  const std::string c = write_file("nan_b.ply", bin);
  expect_error([&] { read_cloud(c); }, ErrorCode::kInvalidArgument, c, "point 1");
  const std::string x = write_file("nan.xyz", "1 2 3\n4 5 NaN\n");
  expect_error([&] { read_cloud(x); }, ErrorCode::kInvalidArgument, x, "line 2: point 1");
  const std::string y = write_file("inf.xyz", "# c\n1 2 3\n4 5 6\ninf 5 6\n");
  expect_error([&] { read_cloud(y); }, ErrorCode::kInvalidArgument, y, "line 4: point 2");
}

TEST_F(CloudIoTest, GarbageNumbersInText) {
  const std::string ply = write_file("garbage.ply", "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
                                                    "property float y\nproperty float z\nend_header\n1 2 3\n4 5x 6\n");
  expect_error([&] { read_cloud(ply); }, ErrorCode::kInvalidArgument, ply, "line 9");
  const std::string xyz = write_file("garbage.xyz", "1 2 3\n4 five 6\n");
  expect_error([&] { read_cloud(xyz); }, ErrorCode::kInvalidArgument, xyz, "line 2");
  const std::string pcd = write_file("garbage.pcd", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\n"
                                                    "HEIGHT 1\nPOINTS 2\nDATA ascii\n1 2 3\n4 5 0x6\n");
  expect_error([&] { read_cloud(pcd); }, ErrorCode::kInvalidArgument, pcd, "line 10");
  const std::string cols = write_file("cols.xyz", "1 2 3 4\n1 2 3\n");
  expect_error([&] { read_cloud(cols); }, ErrorCode::kInvalidArgument, cols, "inconsistent columns");
  const std::string two = write_file("two.xyz", "1 2\n3 4\n");
  expect_error([&] { read_xyz(two); }, ErrorCode::kInvalidArgument, two, "at least 3");
  const std::string late_header = write_file("late.csv", "1,2,3\nx,y,z\n");
  expect_error([&] { read_cloud(late_header); }, ErrorCode::kInvalidArgument, late_header, "line 2");
}

TEST_F(CloudIoTest, MaxPointsIsResourceExhausted) {
  const PointCloud c = small_cloud(false, false);  // 201 points
  ReadOptions limit;
  limit.max_points = 200;
  for (const char* name : {"m.ply", "m.pcd", "m.xyz"}) {
    const std::string p = path(name);
    write_cloud(p, c);
    expect_error([&] { read_cloud(p, limit); }, ErrorCode::kResourceExhausted, p, "200");
  }
  write_pcd(path("mc.pcd"), c, PcdEncoding::kBinaryCompressed);
  expect_error([&] { read_cloud(path("mc.pcd"), limit); }, ErrorCode::kResourceExhausted, "mc.pcd");
  limit.max_points = 201;
  EXPECT_EQ(read_cloud(path("m.ply"), limit).size(), 201u);
  EXPECT_EQ(read_cloud(path("m.xyz"), limit).size(), 201u);
}

// ------------------------------------------------------------------------------------------------
// Real scans (tests/data)
// ------------------------------------------------------------------------------------------------

TEST(RealScansTest, StanfordBunnyAsciiOriginalsAndBinaryCopies) {
  const std::string dir = kData + "/bunny/";
  for (const auto& [name, count] : {std::pair<const char*, std::size_t>{"bun000.ply", 40256}, {"bun045.ply", 40097}}) {
    SCOPED_TRACE(name);
    const PointCloud ascii = read_cloud(dir + "ascii/" + name);  // has the range_grid list element
    const PointCloud binary = read_cloud(dir + name);
    ASSERT_EQ(ascii.size(), count);
    ASSERT_EQ(binary.size(), count);
    EXPECT_FALSE(ascii.has_intensity());
    EXPECT_TRUE(ascii.origin_m.isZero());
    double worst = 0;
    for (std::size_t i = 0; i < count; ++i) worst = std::max(worst, (world(ascii, i) - world(binary, i)).norm());
    EXPECT_LT(worst, 1e-6);
    const Eigen::Vector3f extent = ascii.points[0].cwiseAbs();
    EXPECT_LT(extent.maxCoeff(), 0.3f);  // metres, bunny ≈ 0.15 m
  }
  const std::pair<const char*, std::size_t> derived[] = {
      {"bun090.ply", 30379}, {"bun180.ply", 40251}, {"bun270.ply", 31701}, {"bun315.ply", 35336},
      {"chin.ply", 37738},   {"ear_back.ply", 32193}, {"top2.ply", 38298},  {"top3.ply", 36023}};
  for (const auto& [name, count] : derived) EXPECT_EQ(read_cloud(dir + name).size(), count) << name;
}

TEST(RealScansTest, EthOfficeKeypointsWithIntensity) {
  for (const auto& [name, count] :
       {std::pair<const char*, std::size_t>{"office1_keypoints.pcd", 1318}, {"office2_keypoints.pcd", 1123}}) {
    SCOPED_TRACE(name);
    const PointCloud c = read_cloud(kData + "/eth-office/" + name);
    ASSERT_EQ(c.size(), count);
    ASSERT_TRUE(c.has_intensity());
    const auto [lo, hi] = std::minmax_element(c.intensity.begin(), c.intensity.end());
    EXPECT_GE(*lo, 0.19f);
    EXPECT_LE(*hi, 1.01f);
  }
}

TEST(RealScansTest, VelodynePairWithIntensity) {
  for (const auto& [name, count] :
       {std::pair<const char*, std::size_t>{"251370668.pcd", 69088}, {"251371071.pcd", 69792}}) {
    SCOPED_TRACE(name);
    const PointCloud c = read_cloud(kData + "/velodyne/" + name);
    ASSERT_EQ(c.size(), count);
    ASSERT_TRUE(c.has_intensity());
    const auto [lo, hi] = std::minmax_element(c.intensity.begin(), c.intensity.end());
    EXPECT_GE(*lo, 0.0f);
    EXPECT_LE(*hi, 255.0f);
    float max_range = 0;
    for (const auto& p : c.points) max_range = std::max(max_range, p.norm());
    EXPECT_GT(max_range, 50.0f);
    EXPECT_LT(max_range, 120.0f);
  }
}

// ------------------------------------------------------------------------------------------------
// gt_pairs.log
// ------------------------------------------------------------------------------------------------

TEST(GtPairsTest, ReadsTheShippedLogs) {
  const auto bunny = read_gt_pairs(kData + "/bunny/gt_pairs.log");
  ASSERT_EQ(bunny.size(), 23u);
  EXPECT_EQ(bunny[0].source, "bun045.ply");
  EXPECT_EQ(bunny[0].target, "bun000.ply");
  EXPECT_DOUBLE_EQ(bunny[0].overlap, 0.914);
  EXPECT_DOUBLE_EQ(bunny[0].inlier_rmse, 0.000355137);
  EXPECT_DOUBLE_EQ(bunny[0].T_target_source(0, 0), 0.8263505876);
  EXPECT_DOUBLE_EQ(bunny[0].T_target_source(2, 3), -0.0109223);
  for (const GtPair& p : bunny) {
    EXPECT_TRUE(p.T_target_source.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1)));
    const Eigen::Matrix3d R = p.T_target_source.topLeftCorner<3, 3>();
    EXPECT_TRUE((R * R.transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-6)) << p.source << " " << p.target;
    EXPECT_TRUE(fs::exists(kData + "/bunny/" + p.source)) << p.source;
    EXPECT_TRUE(fs::exists(kData + "/bunny/" + p.target)) << p.target;
  }
  const auto office = read_gt_pairs(kData + "/eth-office/gt_pairs.log");
  ASSERT_EQ(office.size(), 1u);
  EXPECT_EQ(office[0].source, "office1_keypoints.pcd");
  EXPECT_EQ(office[0].target, "office2_keypoints.pcd");
  EXPECT_DOUBLE_EQ(office[0].T_target_source(0, 3), -3.6352);
  const auto velodyne = read_gt_pairs(kData + "/velodyne/gt_pairs.log");
  ASSERT_EQ(velodyne.size(), 1u);
  EXPECT_EQ(velodyne[0].source, "251371071.pcd");
  EXPECT_EQ(velodyne[0].target, "251370668.pcd");
  EXPECT_DOUBLE_EQ(velodyne[0].T_target_source(0, 3), 0.485657);
  EXPECT_DOUBLE_EQ(velodyne[0].overlap, 0.829);
}

TEST_F(CloudIoTest, GtPairsMalformed) {
  const std::string rows = write_file("short.log", "# c\na.ply b.ply 0.5 0.01\n1 0 0 0\n0 1 0 0\n0 0 1 0\n");
  expect_error([&] { read_gt_pairs(rows); }, ErrorCode::kInvalidArgument, rows, "truncated");
  const std::string bad = write_file("bad.log", "a.ply b.ply 0.5 0.01\n1 0 0 0\n0 1 0 0\n0 0 x 0\n0 0 0 1\n");
  expect_error([&] { read_gt_pairs(bad); }, ErrorCode::kInvalidArgument, bad, "line 4");
  const std::string empty = write_file("empty.log", "# only comments\n");
  expect_error([&] { read_gt_pairs(empty); }, ErrorCode::kInvalidArgument, empty, "no pairs");
}

// ------------------------------------------------------------------------------------------------
// Throughput (not part of the suite: run with --gtest_also_run_disabled_tests)
// ------------------------------------------------------------------------------------------------

TEST(CloudIoBenchmark, DISABLED_ReadTenMillionPointBinaryPly) {
  const std::size_t n = 10'000'000;
  PointCloud c;
  c.points.resize(n);
  c.intensity.resize(n);
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(-100.0f, 100.0f);
  for (std::size_t i = 0; i < n; ++i) {
    c.points[i] = Eigen::Vector3f(u(rng), u(rng), u(rng));
    c.intensity[i] = static_cast<float>(i % 4096);
  }
  const std::string p = (fs::temp_directory_path() / ("k4reg_10m_" + std::to_string(::getpid()) + ".ply")).string();
  write_ply(p, c);
  PointCloud r = read_cloud(p);  // warm the page cache
  const auto t0 = std::chrono::steady_clock::now();
  r = read_cloud(p);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("read_cloud: %zu points (%.0f MB) in %.3f s\n", r.size(), fs::file_size(p) / 1e6, s);
  fs::remove(p);
  ASSERT_EQ(r.size(), n);
  EXPECT_LT(s, 2.0);
}

}  // namespace
}  // namespace k4reg
