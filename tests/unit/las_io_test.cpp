// LAS reader and writer: round trips over every point format and version, hand-built headers (independent of
// the writer), legacy vs 64-bit point counts, extra bytes, intensity normalisation, LAZ refusal, malformed files.
#include "k4reg/io/las_io.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <random>
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

class LasIoTest : public test::TempDirTest {};

PointCloud test_cloud(const Eigen::Vector3d& base, bool with_intensity) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-30.0, 30.0);
  std::vector<Eigen::Vector3d> pts;
  std::vector<float> intensity;
  for (int i = 0; i < 500; ++i) {
    pts.push_back(base + Eigen::Vector3d(u(rng), u(rng), 0.2 * u(rng)));
    intensity.push_back(static_cast<float>(i % 97) / 96.0f);
  }
  return make_local_cloud(pts, with_intensity ? intensity : std::vector<float>{}, "test");
}

template <typename T>
void put(std::string& s, T v) {
  s.append(reinterpret_cast<const char*>(&v), sizeof v);
}

// A LAS header built field by field from the specification (not by write_las).
struct HandHeader {
  int minor = 2;
  int format = 1;
  std::uint16_t record_length = 28;
  std::uint32_t legacy_count = 0;
  std::uint64_t count64 = 0;
  std::uint32_t vlrs = 0;
  std::string vlr_bytes;
  double scale = 0.01;
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();

  std::string bytes() const {
    const std::uint16_t header_size = minor >= 4 ? 375 : minor == 3 ? 235 : 227;
    std::string h = "LASF";
    put<std::uint16_t>(h, 0);
    put<std::uint16_t>(h, 0);
    h.append(16, '\0');
    h += '\1';
    h += static_cast<char>(minor);
    h.append(64, ' ');
    put<std::uint16_t>(h, 1);
    put<std::uint16_t>(h, 2024);
    put<std::uint16_t>(h, header_size);
    put<std::uint32_t>(h, static_cast<std::uint32_t>(header_size + vlr_bytes.size()));
    put<std::uint32_t>(h, vlrs);
    h += static_cast<char>(format);
    put<std::uint16_t>(h, record_length);
    put<std::uint32_t>(h, legacy_count);
    for (int r = 0; r < 5; ++r) put<std::uint32_t>(h, 0);
    for (int a = 0; a < 3; ++a) put<double>(h, scale);
    for (int a = 0; a < 3; ++a) put<double>(h, offset[a]);
    for (int a = 0; a < 6; ++a) put<double>(h, 0.0);
    if (minor >= 3) put<std::uint64_t>(h, 0);
    if (minor >= 4) {
      put<std::uint64_t>(h, 0);
      put<std::uint32_t>(h, 0);
      put<std::uint64_t>(h, count64);
      for (int r = 0; r < 15; ++r) put<std::uint64_t>(h, 0);
    }
    EXPECT_EQ(h.size(), header_size);
    return h + vlr_bytes;
  }
};

std::string record(std::int32_t x, std::int32_t y, std::int32_t z, std::uint16_t intensity, std::size_t length) {
  std::string r;
  put(r, x);
  put(r, y);
  put(r, z);
  put(r, intensity);
  r.resize(length, '\x5A');  // the other fields and extra bytes: anything
  return r;
}

std::string vlr(const std::string& user, std::uint16_t id, const std::string& payload) {
  std::string v;
  put<std::uint16_t>(v, 0);
  std::string u = user;
  u.resize(16, '\0');
  v += u;
  put<std::uint16_t>(v, id);
  put<std::uint16_t>(v, static_cast<std::uint16_t>(payload.size()));
  v.append(32, '\0');
  return v + payload;
}

TEST_F(LasIoTest, RoundTripEveryPointFormatAndVersion) {
  const PointCloud utm = test_cloud(Eigen::Vector3d(512345.678, 5240123.456, 312.5), true);
  const PointCloud local = test_cloud(Eigen::Vector3d::Zero(), false);
  for (int minor : {2, 3, 4}) {
    for (int format = 0; format <= 10; ++format) {
      if ((format >= 6 && minor < 4) || (format >= 4 && minor < 3)) continue;
      for (std::size_t extra : {std::size_t{0}, std::size_t{7}}) {
        for (const PointCloud* cloud : {&utm, &local}) {
          SCOPED_TRACE(::testing::Message() << "1." << minor << " format " << format << " extra " << extra);
          LasWriteOptions options;
          options.version_minor = minor;
          options.point_format = format;
          options.extra_bytes = extra;
          const std::string p = path("rt.las");
          write_las(p, *cloud, options);
          EXPECT_EQ(detect_format(p), CloudFormat::kLas);
          const PointCloud r = read_cloud(p);
          ASSERT_EQ(r.size(), cloud->size());
          ASSERT_EQ(r.has_intensity(), cloud->has_intensity());
          double worst = 0;
          for (std::size_t i = 0; i < r.size(); ++i) {
            worst = std::max(worst, (world(r, i) - world(*cloud, i)).cwiseAbs().maxCoeff());
            if (r.has_intensity()) {
              EXPECT_NEAR(r.intensity[i], cloud->intensity[i], 1.0 / 65535) << i;
            }
          }
          EXPECT_LE(worst, 0.5 * options.resolution_m + 2e-6);  // quantisation + float offsets, also at UTM
          EXPECT_EQ(r.origin_m.isZero(), cloud->origin_m.isZero());
        }
      }
    }
  }
}

TEST_F(LasIoTest, HandBuiltLegacyFileWithVlrsAndExtraBytes) {
  HandHeader h;
  h.minor = 2;
  h.format = 1;
  h.record_length = 28 + 5;  // 5 undescribed extra bytes
  h.legacy_count = 3;
  h.vlrs = 2;
  h.vlr_bytes = vlr("LASF_Projection", 34735, std::string(40, '\1')) + vlr("someone", 7, "hello");
  h.scale = 0.000001;  // the int32 extremes span 4.3 km: float offsets from the centre hold them to 0.1 mm
  h.offset = Eigen::Vector3d(500000, 5240000, 300);
  const std::string bytes = h.bytes() + record(1234567, -5678, 9, 65535, 33) + record(0, 0, 0, 0, 33) +
                            record(-2147483647 - 1, 2147483647, -1, 32768, 33);
  const PointCloud c = read_cloud(write_file("hand.las", bytes));
  EXPECT_EQ(detect_format(write_file("hand.xyz", bytes)), CloudFormat::kLas);  // the magic wins over the extension
  ASSERT_EQ(c.size(), 3u);
  EXPECT_LT((world(c, 0) - Eigen::Vector3d(500001.234567, 5239999.994322, 300.000009)).norm(), 1e-4);
  EXPECT_LT((world(c, 1) - Eigen::Vector3d(500000, 5240000, 300)).norm(), 1e-4);
  EXPECT_LT((world(c, 2) - Eigen::Vector3d(500000 - 2147.483648, 5240000 + 2147.483647, 299.999999)).norm(), 1e-4);
  ASSERT_TRUE(c.has_intensity());
  EXPECT_FLOAT_EQ(c.intensity[0], 1.0f);  // 16-bit value / 65535
  EXPECT_FLOAT_EQ(c.intensity[1], 0.0f);
  EXPECT_NEAR(c.intensity[2], 32768.0 / 65535.0, 1e-7);
}

TEST_F(LasIoTest, PointCountsLegacyAnd64Bit) {
  // LAS 1.4 point format 6: legacy count 0, the 64-bit count holds the points.
  HandHeader h;
  h.minor = 4;
  h.format = 6;
  h.record_length = 30;
  h.count64 = 2;
  const std::string points = record(100, 200, 300, 7, 30) + record(-100, -200, -300, 9, 30);
  PointCloud c = read_cloud(write_file("v14.las", h.bytes() + points));
  ASSERT_EQ(c.size(), 2u);
  EXPECT_LT((world(c, 1) - Eigen::Vector3d(-1, -2, -3)).norm(), 1e-9);
  // LAS 1.4 with a legacy format: both counts set (they agree); only the legacy one set (older writers).
  h.format = 1;
  h.record_length = 28;
  h.legacy_count = 2;
  const std::string points1 = record(100, 200, 300, 7, 28) + record(-100, -200, -300, 9, 28);
  EXPECT_EQ(read_cloud(write_file("both.las", h.bytes() + points1)).size(), 2u);
  h.count64 = 0;
  EXPECT_EQ(read_cloud(write_file("legacy.las", h.bytes() + points1)).size(), 2u);
  // LAS 1.2 ignores bytes past its 227-byte header: a record after the points (EVLR-like trailer) is fine.
  HandHeader old;
  old.legacy_count = 1;
  EXPECT_EQ(read_cloud(write_file("trailer.las", old.bytes() + record(1, 2, 3, 4, 28) + "TRAILER")).size(), 1u);
}

TEST_F(LasIoTest, ConstantIntensityIsNoIntensity) {
  HandHeader h;
  h.legacy_count = 3;
  std::string points;
  for (int i = 0; i < 3; ++i) points += record(i, i * i, 5, 0, 28);
  const PointCloud zero = read_cloud(write_file("zero.las", h.bytes() + points));
  EXPECT_EQ(zero.size(), 3u);
  EXPECT_FALSE(zero.has_intensity());
  // Written without intensity → the writer stores 0 → read back without intensity.
  const PointCloud plain = test_cloud(Eigen::Vector3d::Zero(), false);
  write_las(path("plain.las"), plain);
  EXPECT_FALSE(read_las(path("plain.las")).has_intensity());
  // The writer maps [0, max(1, largest)] onto 0–65535: raw intensities 0–4095 come back as value / 4095.
  PointCloud raw = plain;
  for (std::size_t i = 0; i < raw.size(); ++i) raw.intensity.push_back(static_cast<float>(i * 8 % 4096));
  raw.intensity[0] = 4095.0f;
  write_las(path("raw.las"), raw);
  const PointCloud back = read_las(path("raw.las"));
  for (std::size_t i = 0; i < raw.size(); ++i) EXPECT_NEAR(back.intensity[i], raw.intensity[i] / 4095.0, 1.0 / 65535) << i;
}

TEST_F(LasIoTest, LazIsRefusedWithAClearMessage) {
  HandHeader h;
  h.legacy_count = 1;
  h.format = 1 | 0x80;  // LASzip sets the compression bit
  const std::string laz = write_file("scan.laz", h.bytes() + std::string(50, '\0'));
  expect_error([&] { read_cloud(laz); }, ErrorCode::kInvalidArgument, laz, "LAZ is not supported; decompress with laszip or pdal first");
  // The same bytes named .las, and a file marked only by the LASzip VLR.
  expect_error([&] { read_cloud(write_file("named.las", read_bytes(laz))); }, ErrorCode::kInvalidArgument, "named.las", "LAZ");
  HandHeader v;
  v.legacy_count = 1;
  v.vlrs = 1;
  v.vlr_bytes = vlr("laszip encoded", 22204, std::string(34, '\0'));
  expect_error([&] { read_cloud(write_file("vlr.las", v.bytes() + record(1, 2, 3, 4, 28))); },
               ErrorCode::kInvalidArgument, "vlr.las", "LAZ");
  expect_error([&] { format_from_extension("out.laz"); }, ErrorCode::kInvalidArgument, "out.laz", "LAZ is not supported");
  expect_error([&] { write_cloud(path("out.laz"), test_cloud(Eigen::Vector3d::Zero(), false)); },
               ErrorCode::kInvalidArgument, "out.laz", "LAZ");
}

TEST_F(LasIoTest, MalformedHeadersAreClearErrors) {
  HandHeader good;
  good.legacy_count = 1;
  const std::string body = record(1, 2, 3, 4, 28);
  const std::string ok = good.bytes();
  auto patched = [&](std::size_t at, const std::string& bytes) {
    std::string b = ok;
    b.replace(at, bytes.size(), bytes);
    return b + body;
  };
  auto u16 = [](std::uint16_t v) { return std::string(reinterpret_cast<const char*>(&v), 2); };
  auto u32 = [](std::uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  const struct {
    const char* name;
    std::string bytes;
    const char* needle;
  } cases[] = {
      {"magic.las", "LASX" + ok.substr(4) + body, "wrong magic"},
      {"short.las", ok.substr(0, 100), "truncated"},
      {"version.las", patched(24, std::string("\2\0", 2)), "version 2.0"},
      {"minor.las", patched(25, "\7"), "version 1.7"},
      {"headersize.las", patched(94, u16(200)), "header size 200"},
      {"offset.las", patched(96, u32(1u << 30)), "offset to point data"},
      {"format.las", patched(104, "\x0b"), "point data record format 11"},
      {"reclen.las", patched(105, u16(12)), "record length 12"},
      {"scale.las", patched(131, std::string(8, '\0')), "scale"},
      {"nopoints.las", patched(107, u32(0)), "no points"},
      {"truncated.las", patched(107, u32(2)), "truncated"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string p = write_file(c.name, c.bytes);
    expect_error([&] { read_las(p); }, ErrorCode::kInvalidArgument, p, c.needle);
  }
  expect_error([&] { read_cloud(write_file("empty.las", "")); }, ErrorCode::kInvalidArgument, "empty.las", "empty");
}

TEST_F(LasIoTest, HugeClaimsAreRefusedInstantlyAndMaxPointsHolds) {
  HandHeader h;
  h.minor = 4;
  h.format = 6;
  h.record_length = 30;
  h.count64 = 1000000000000ull;
  const std::string p = write_file("huge.las", h.bytes() + record(1, 2, 3, 4, 30));
  EXPECT_LT(fs::file_size(p), 500u);
  const auto t0 = std::chrono::steady_clock::now();
  expect_error([&] { read_cloud(p); }, ErrorCode::kInvalidArgument, p, "truncated");
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::milliseconds(100));

  write_las(path("five.las"), test_cloud(Eigen::Vector3d::Zero(), true));
  ReadOptions limited;
  limited.max_points = 499;
  expect_error([&] { read_cloud(path("five.las"), limited); }, ErrorCode::kResourceExhausted, "five.las", "499");
  limited.max_points = 500;
  EXPECT_EQ(read_cloud(path("five.las"), limited).size(), 500u);
  ReadOptions scan;
  scan.scan_index = 0;
  expect_error([&] { read_cloud(path("five.las"), scan); }, ErrorCode::kInvalidArgument, "five.las", "scan selection");
}

TEST_F(LasIoTest, WriterRefusesBadOptionsAndGrowsTheScaleForLargeExtents) {
  const PointCloud c = test_cloud(Eigen::Vector3d::Zero(), false);
  LasWriteOptions bad;
  bad.version_minor = 2;
  bad.point_format = 6;
  expect_error([&] { write_las(path("bad.las"), c, bad); }, ErrorCode::kInvalidArgument, "bad.las", "needs LAS 1.4");
  bad = {};
  bad.point_format = 11;
  expect_error([&] { write_las(path("bad.las"), c, bad); }, ErrorCode::kInvalidArgument, "bad.las", "point format 11");
  expect_error([&] { write_las(path("empty.las"), PointCloud{}); }, ErrorCode::kInvalidArgument, "empty.las", "without points");
  // 600 km across at 0.1 mm does not fit int32: the scale grows to 1 mm.
  const PointCloud wide = make_local_cloud({Eigen::Vector3d(-300000, 0, 0), Eigen::Vector3d(300000, 1.2345, 0)}, {}, "wide");
  write_las(path("wide.las"), wide);
  const PointCloud r = read_las(path("wide.las"));
  EXPECT_NEAR(world(r, 0).x(), -300000.0, 1e-9);
  EXPECT_NEAR(world(r, 1).y(), 1.235, 1e-6);  // rounded to the mm
}

}  // namespace
}  // namespace k4reg
