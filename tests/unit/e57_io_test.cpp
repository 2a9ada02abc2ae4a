// E57 reader and writer. Two sources of files: write_e57 (round trips: every coordinate encoding, several scans
// with poses, scan selection, invalid states, intensity) and a small assembler in this test that builds files
// from the standard's layout independently of the core's writer (bit widths 1–64 with values straddling data
// packets, index/empty packets, nested prototypes, bad XML, bad packets). Damage: every byte flipped in turn
// (a CRC-32C mismatch is kDataLoss, never a crash), truncation, huge record counts.
#include "k4reg/io/e57_io.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "k4reg/io/cloud_io.h"
#include "k4reg/util/crc32c.h"
#include "k4reg/util/error.h"
#include "io_test_support.h"

namespace k4reg {
namespace {

namespace fs = std::filesystem;
using test::expect_error;
using test::world;

class E57IoTest : public test::TempDirTest {};

PointCloud scan_cloud(const Eigen::Vector3d& base, std::size_t n, std::uint32_t seed, bool with_intensity) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-25.0, 25.0);
  std::vector<Eigen::Vector3d> pts;
  std::vector<float> intensity;
  for (std::size_t i = 0; i < n; ++i) {
    pts.push_back(base + Eigen::Vector3d(u(rng), u(rng), 0.3 * u(rng)));
    intensity.push_back(static_cast<float>(i % 1000) * 0.003f - 0.5f);
  }
  return make_local_cloud(pts, with_intensity ? intensity : std::vector<float>{}, "scan");
}

E57Scan make_scan(std::string name, PointCloud cloud, const Eigen::Isometry3d& pose = Eigen::Isometry3d::Identity()) {
  E57Scan scan;
  scan.name = std::move(name);
  scan.cloud = std::move(cloud);
  scan.pose = pose;
  return scan;
}

double max_error(const PointCloud& read, const std::vector<Eigen::Vector3d>& expected) {
  EXPECT_EQ(read.size(), expected.size());
  double worst = 0;
  for (std::size_t i = 0; i < std::min(read.size(), expected.size()); ++i)
    worst = std::max(worst, (world(read, i) - expected[i]).norm());
  return worst;
}

std::vector<Eigen::Vector3d> posed(const E57Scan& scan) {
  std::vector<Eigen::Vector3d> out;
  for (std::size_t i = 0; i < scan.cloud.size(); ++i) out.push_back(scan.pose * world(scan.cloud, i));
  return out;
}

// ------------------------------------------------------------------------------------------------
// An E57 assembler independent of write_e57: header, CompressedVector sections from raw packets, the XML given
// as text with "@OFFSET<i>@" where section i's physical offset goes, 1024-byte pages with CRC-32C stored most
// significant byte first.
// ------------------------------------------------------------------------------------------------

template <typename T>
void put(std::string& s, T v) {
  s.append(reinterpret_cast<const char*>(&v), sizeof v);
}

std::uint64_t physical(std::uint64_t logical) { return logical / 1020 * 1024 + logical % 1020; }

std::string paged(const std::string& logical) {
  std::string file;
  for (std::size_t at = 0; at < logical.size(); at += 1020) {
    std::string page = logical.substr(at, 1020);
    page.resize(1020, '\0');
    const std::uint32_t crc = crc32c(page);
    for (int k = 3; k >= 0; --k) page += static_cast<char>(crc >> (8 * k));
    file += page;
  }
  return file;
}

std::string assemble(const std::vector<std::string>& sections_packets, std::string xml) {
  std::string logical(48, '\0');
  for (std::size_t s = 0; s < sections_packets.size(); ++s) {
    const std::uint64_t start = logical.size();
    std::string header(1, '\1');
    header.append(7, '\0');
    put<std::uint64_t>(header, 32 + sections_packets[s].size());
    put<std::uint64_t>(header, physical(start + 32));
    put<std::uint64_t>(header, 0);
    logical += header + sections_packets[s];
    const std::string key = "@OFFSET" + std::to_string(s) + "@";
    for (std::size_t p; (p = xml.find(key)) != std::string::npos;) xml.replace(p, key.size(), std::to_string(physical(start)));
  }
  const std::uint64_t xml_logical = logical.size();
  logical += xml;
  const std::uint64_t pages = (logical.size() + 1019) / 1020;
  std::string header = "ASTM-E57";
  put<std::uint32_t>(header, 1);
  put<std::uint32_t>(header, 0);
  put<std::uint64_t>(header, pages * 1024);
  put<std::uint64_t>(header, physical(xml_logical));
  put<std::uint64_t>(header, xml.size());
  put<std::uint64_t>(header, 1024);
  logical.replace(0, 48, header);
  return paged(logical);
}

// Values packed least significant bit first, one bit at a time (deliberately naive).
std::string pack(const std::vector<std::uint64_t>& values, unsigned bits) {
  std::string out;
  std::size_t position = 0;
  for (std::uint64_t v : values)
    for (unsigned b = 0; b < bits; ++b, ++position) {
      if (position % 8 == 0) out += '\0';
      if ((v >> b) & 1) out.back() = static_cast<char>(out.back() | (1 << (position % 8)));
    }
  return out;
}

std::string data_packet(const std::vector<std::string>& streams) {
  std::string p(1, '\1');
  p += '\0';
  put<std::uint16_t>(p, 0);  // length - 1, set below
  put<std::uint16_t>(p, static_cast<std::uint16_t>(streams.size()));
  for (const std::string& s : streams) put<std::uint16_t>(p, static_cast<std::uint16_t>(s.size()));
  for (const std::string& s : streams) p += s;
  p.resize((p.size() + 3) / 4 * 4, '\0');
  const std::uint16_t minus1 = static_cast<std::uint16_t>(p.size() - 1);
  std::memcpy(p.data() + 2, &minus1, 2);
  return p;
}

std::string index_packet() {
  std::string p(1, '\0');
  p += '\0';
  put<std::uint16_t>(p, 32 - 1);
  put<std::uint16_t>(p, 1);  // entry count
  p.append(10, '\0');
  put<std::uint64_t>(p, 0);
  put<std::uint64_t>(p, 0);
  return p;
}

std::string empty_packet() {
  std::string p(1, '\2');
  p += '\0';
  put<std::uint16_t>(p, 8 - 1);
  p.append(4, '\0');
  return p;
}

std::string xml_file(const std::string& data3d_children) {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
         "<e57Root type=\"Structure\" xmlns=\"http://www.astm.org/COMMIT/E57/2010-e57-v1.0\">\n"
         "  <formatName type=\"String\"><![CDATA[ASTM E57 3D Imaging Data File]]></formatName>\n"
         "  <guid type=\"String\"><![CDATA[{T}]]></guid>\n"
         "  <versionMajor type=\"Integer\">1</versionMajor><versionMinor type=\"Integer\">0</versionMinor>\n"
         "  <data3D type=\"Vector\" allowHeterogeneousChildren=\"1\">\n" +
         data3d_children + "  </data3D>\n</e57Root>\n";
}

std::string scan_xml(const std::string& name, std::size_t section, std::uint64_t records, const std::string& prototype,
                     const std::string& extra = "") {
  return "    <vectorChild type=\"Structure\">\n      <guid type=\"String\"><![CDATA[{S}]]></guid>\n"
         "      <name type=\"String\"><![CDATA[" + name + "]]></name>\n" + extra +
         "      <points type=\"CompressedVector\" fileOffset=\"@OFFSET" + std::to_string(section) + "@\" recordCount=\"" +
         std::to_string(records) + "\">\n        <prototype type=\"Structure\">" + prototype +
         "</prototype>\n        <codecs type=\"Vector\" allowHeterogeneousChildren=\"1\"/>\n      </points>\n"
         "    </vectorChild>\n";
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

std::vector<std::uint64_t> doubles(const std::vector<double>& v) {
  std::vector<std::uint64_t> raw;
  for (double d : v) raw.push_back(std::bit_cast<std::uint64_t>(d));
  return raw;
}

// ------------------------------------------------------------------------------------------------
// Round trips through write_e57
// ------------------------------------------------------------------------------------------------

TEST_F(E57IoTest, RoundTripEveryCoordinateEncoding) {
  const PointCloud utm = scan_cloud(Eigen::Vector3d(512345.678, 5240123.456, 312.5), 3000, 1, true);
  const PointCloud local = scan_cloud(Eigen::Vector3d(3, -4, 1), 3000, 2, true);
  const struct {
    E57Coordinates coordinates;
    const PointCloud* cloud;
    double tolerance_m;
  } cases[] = {
      {E57Coordinates::kCartesianDouble, &utm, 1e-9},
      {E57Coordinates::kCartesianDouble, &local, 1e-9},
      {E57Coordinates::kCartesianSingle, &local, 4e-6},  // float32 of coordinates up to ~35 m
      {E57Coordinates::kCartesianScaledInteger, &utm, 0.5e-4 * std::sqrt(3.0) + 2e-6},
      {E57Coordinates::kSphericalDouble, &local, 1e-9},
      {E57Coordinates::kSphericalDouble, &utm, 1e-6},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(::testing::Message() << "encoding " << static_cast<int>(c.coordinates) << " utm " << (c.cloud == &utm));
    E57WriteOptions options;
    options.coordinates = c.coordinates;
    const std::string p = path("rt.e57");
    write_e57(p, {make_scan("only", *c.cloud)}, options);
    EXPECT_EQ(fs::file_size(p) % 1024, 0u);
    EXPECT_EQ(detect_format(p), CloudFormat::kE57);
    const PointCloud r = read_cloud(p);
    std::vector<Eigen::Vector3d> expected;
    for (std::size_t i = 0; i < c.cloud->size(); ++i) expected.push_back(world(*c.cloud, i));
    EXPECT_LE(max_error(r, expected), c.tolerance_m);
    // Intensity comes back normalised by intensityLimits (the values' range).
    ASSERT_TRUE(r.has_intensity());
    const auto [lo, hi] = std::minmax_element(c.cloud->intensity.begin(), c.cloud->intensity.end());
    for (std::size_t i = 0; i < r.size(); ++i) ASSERT_NEAR(r.intensity[i], (c.cloud->intensity[i] - *lo) / (*hi - *lo), 1e-6) << i;
  }
  // write_cloud's .e57: one scan of doubles; detected by its magic under any name.
  write_cloud(path("wc.e57"), utm);
  EXPECT_EQ(read_cloud(path("wc.e57")).size(), utm.size());
  fs::rename(path("wc.e57"), path("wc.ply"));
  EXPECT_EQ(detect_format(path("wc.ply")), CloudFormat::kE57);
}

TEST_F(E57IoTest, IntegerIntensityOfAnyWidthIsNormalisedByItsLimits) {
  const PointCloud c = scan_cloud(Eigen::Vector3d::Zero(), 2000, 3, true);
  const auto [lo, hi] = std::minmax_element(c.intensity.begin(), c.intensity.end());
  for (int bits : {1, 3, 11, 16, 21, 32}) {
    SCOPED_TRACE(bits);
    E57WriteOptions options;
    options.intensity_bits = bits;
    write_e57(path("i.e57"), {make_scan("s", c)}, options);
    const PointCloud r = read_e57(path("i.e57"));
    ASSERT_TRUE(r.has_intensity());
    const double top = std::ldexp(1.0, bits) - 1;
    for (std::size_t i = 0; i < r.size(); ++i) {
      const double expected = std::round((double{c.intensity[i]} - *lo) / (double{*hi} - *lo) * top) / top;
      ASSERT_NEAR(r.intensity[i], expected, 1e-6) << i;
    }
  }
}

TEST_F(E57IoTest, SeveralScansWithPosesMergeOrAreSelectedByIndexOrName) {
  std::vector<E57Scan> scans;
  for (int s = 0; s < 3; ++s) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = Eigen::AngleAxisd(0.9 * s + 0.2, Eigen::Vector3d(0.1, -0.2, 1).normalized()).toRotationMatrix();
    pose.translation() = Eigen::Vector3d(500000 + 40.0 * s, 5240000 + 15.0 * s, 300 + 0.5 * s);
    scans.push_back(make_scan("Station " + std::to_string(s + 1), scan_cloud(Eigen::Vector3d::Zero(), 1500 + 100 * s, 10 + s, true), pose));
  }
  scans[1].name = "Station ]]> <&> 2";  // survives CDATA and XML escaping
  for (E57Coordinates coordinates : {E57Coordinates::kCartesianDouble, E57Coordinates::kCartesianScaledInteger,
                                     E57Coordinates::kSphericalDouble}) {
    SCOPED_TRACE(static_cast<int>(coordinates));
    E57WriteOptions options;
    options.coordinates = coordinates;
    const std::string p = path("project.e57");
    write_e57(p, scans, options);
    // Float offsets over a 100 m project: ~4 µm; plus 0.05 mm quantisation per axis for ScaledInteger.
    const double tolerance = coordinates == E57Coordinates::kCartesianScaledInteger ? 1e-4 : 1e-5;
    std::vector<Eigen::Vector3d> all;
    for (const E57Scan& s : scans)
      for (const Eigen::Vector3d& q : posed(s)) all.push_back(q);
    const PointCloud merged = read_cloud(p);
    EXPECT_LE(max_error(merged, all), tolerance);
    EXPECT_TRUE(merged.has_intensity());
    ReadOptions by_index;
    by_index.scan_index = 2;
    EXPECT_LE(max_error(read_cloud(p, by_index), posed(scans[2])), tolerance);
    ReadOptions by_name;
    by_name.scan_name = "Station ]]> <&> 2";
    EXPECT_LE(max_error(read_cloud(p, by_name), posed(scans[1])), tolerance);
    // A project reads each scan in its own frame.
    EXPECT_EQ(count_scans(p), 3u);
    ReadOptions own_frame;
    own_frame.scan_index = 1;
    own_frame.apply_pose = false;
    std::vector<Eigen::Vector3d> local;
    for (std::size_t i = 0; i < scans[1].cloud.size(); ++i) local.push_back(world(scans[1].cloud, i));
    EXPECT_LE(max_error(read_cloud(p, own_frame), local), tolerance);
  }
  const std::string p = path("project.e57");
  ReadOptions bad;
  bad.scan_index = 3;
  expect_error([&] { read_cloud(p, bad); }, ErrorCode::kInvalidArgument, p, "scan index 3 does not exist: the file has 3 scans");
  bad = {};
  bad.scan_name = "Station 9";
  expect_error([&] { read_cloud(p, bad); }, ErrorCode::kInvalidArgument, p, "none of its 3 scans is named 'Station 9'");
  bad.scan_index = 0;
  expect_error([&] { read_cloud(p, bad); }, ErrorCode::kInvalidArgument, p, "not both");
  scans[2].name = scans[0].name;
  write_e57(p, scans);
  bad = {};
  bad.scan_name = "Station 1";
  expect_error([&] { read_cloud(p, bad); }, ErrorCode::kInvalidArgument, p, "2 scans are named 'Station 1'");
}

TEST_F(E57IoTest, InvalidStatesAreSkippedAndIntensityNeedsEveryScan) {
  for (E57Coordinates coordinates : {E57Coordinates::kCartesianDouble, E57Coordinates::kSphericalDouble}) {
    E57Scan scan = make_scan("s", scan_cloud(Eigen::Vector3d::Zero(), 500, 4, true));
    scan.invalid_state.resize(scan.cloud.size());
    std::vector<Eigen::Vector3d> valid;
    for (std::size_t i = 0; i < scan.cloud.size(); ++i) {
      scan.invalid_state[i] = static_cast<std::uint8_t>(i % 5 == 0 ? 2 : i % 7 == 0 ? 1 : 0);
      if (scan.invalid_state[i] == 0) valid.push_back(world(scan.cloud, i));
    }
    E57WriteOptions options;
    options.coordinates = coordinates;
    write_e57(path("invalid.e57"), {scan}, options);
    const PointCloud r = read_e57(path("invalid.e57"));
    EXPECT_LE(max_error(r, valid), 2e-6);
    const std::string xml = read_bytes(path("invalid.e57"));
    EXPECT_NE(xml.find(coordinates == E57Coordinates::kSphericalDouble ? "sphericalInvalidState" : "cartesianInvalidState"),
              std::string::npos);
  }
  write_e57(path("mixed.e57"), {make_scan("a", scan_cloud(Eigen::Vector3d::Zero(), 100, 5, true)),
                                make_scan("b", scan_cloud(Eigen::Vector3d::Zero(), 100, 6, false))});
  EXPECT_FALSE(read_e57(path("mixed.e57")).has_intensity());
  ReadOptions first;
  first.scan_index = 0;
  EXPECT_TRUE(read_e57(path("mixed.e57"), first).has_intensity());
}

TEST_F(E57IoTest, ManyPacketsAndTheWriterRefusesBadInput) {
  // 200 000 records of 64+64+64+32 bits: ~50 data packets, straddling page boundaries.
  const PointCloud big = scan_cloud(Eigen::Vector3d(100, 200, 30), 200000, 7, true);
  write_e57(path("big.e57"), {make_scan("big", big)});
  std::vector<Eigen::Vector3d> expected;
  for (std::size_t i = 0; i < big.size(); ++i) expected.push_back(world(big, i));
  EXPECT_LE(max_error(read_e57(path("big.e57")), expected), 1e-9);
  ReadOptions limited;
  limited.max_points = 199999;
  expect_error([&] { read_e57(path("big.e57"), limited); }, ErrorCode::kResourceExhausted, "big.e57", "199999");

  expect_error([&] { write_e57(path("none.e57"), {}); }, ErrorCode::kInvalidArgument, "none.e57", "without scans");
  expect_error([&] { write_e57(path("empty.e57"), {make_scan("e", PointCloud{})}); }, ErrorCode::kInvalidArgument,
               "empty.e57", "no points");
  E57Scan bad_state = make_scan("s", scan_cloud(Eigen::Vector3d::Zero(), 10, 8, false));
  bad_state.invalid_state.assign(9, 0);
  expect_error([&] { write_e57(path("state.e57"), {bad_state}); }, ErrorCode::kInvalidArgument, "state.e57", "one value per point");
  E57WriteOptions options;
  options.intensity_bits = 33;
  expect_error([&] { write_e57(path("bits.e57"), {make_scan("s", big)}, options); }, ErrorCode::kInvalidArgument,
               "bits.e57", "intensity_bits");
}

// ------------------------------------------------------------------------------------------------
// Files from the independent assembler
// ------------------------------------------------------------------------------------------------

TEST_F(E57IoTest, ScaledIntegersOfEveryWidthAcrossPacketsWithIndexAndEmptyPackets) {
  // cartesianX: ScaledInteger over the full signed range of `bits` bits, so every value uses the top bit while
  // staying small; cartesianY: Float double; cartesianZ: a constant (0 bits, no bytes in any packet).
  const std::size_t n = 37;
  for (unsigned bits = 1; bits <= 64; ++bits) {
    SCOPED_TRACE(bits);
    const std::int64_t minimum = bits == 64 ? std::numeric_limits<std::int64_t>::min() : -(std::int64_t{1} << (bits - 1));
    const std::int64_t maximum = bits == 64 ? std::numeric_limits<std::int64_t>::max() : (std::int64_t{1} << (bits - 1)) - 1;
    std::vector<std::uint64_t> x_raw;
    std::vector<double> x, y;
    for (std::size_t i = 0; i < n; ++i) {
      const std::int64_t value = bits == 1 ? -static_cast<std::int64_t>(i % 2) : static_cast<std::int64_t>(i % 3) - 1;
      x_raw.push_back(static_cast<std::uint64_t>(value) - static_cast<std::uint64_t>(minimum));
      x.push_back(value * 0.5 + 10.0);
      y.push_back(0.25 * static_cast<double>(i));
    }
    const std::string xs = pack(x_raw, bits), ys = pack(doubles(y), 64);
    // Split each stream at an odd byte position: values straddle the two data packets.
    const std::size_t xs_cut = xs.size() / 2 + 1, ys_cut = 77;
    const std::string packets = index_packet() + data_packet({xs.substr(0, xs_cut), ys.substr(0, ys_cut), ""}) +
                                empty_packet() + data_packet({xs.substr(xs_cut), ys.substr(ys_cut), ""});
    const std::string prototype =
        "<cartesianX type=\"ScaledInteger\" minimum=\"" + std::to_string(minimum) + "\" maximum=\"" +
        std::to_string(maximum) + "\" scale=\"0.5\" offset=\"10\"/><cartesianY type=\"Float\"/>"
        "<cartesianZ type=\"ScaledInteger\" minimum=\"7\" maximum=\"7\" scale=\"0.001\" offset=\"-2\"/>";
    const std::string p = write_file("bits.e57", assemble({packets}, xml_file(scan_xml("hand", 0, n, prototype))));
    const PointCloud r = read_e57(p);
    ASSERT_EQ(r.size(), n);
    for (std::size_t i = 0; i < n; ++i)
      ASSERT_LT((world(r, i) - Eigen::Vector3d(x[i], y[i], -1.993)).norm(), 1e-6) << i;
  }
}

TEST_F(E57IoTest, StreamsFarOutOfStepAcrossManyPackets) {
  // All of cartesianX first, then all of Y, then all of Z (a writer may send streams in any proportion): the
  // reader holds 70 000 decoded X values until Y and Z arrive.
  const std::size_t n = 70000;
  std::vector<std::uint64_t> raw[3];
  for (std::size_t i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) raw[a].push_back(std::bit_cast<std::uint32_t>(static_cast<float>(i % 1000) * 0.01f + a));
  std::string packets;
  for (int a = 0; a < 3; ++a) {
    const std::string stream = pack(raw[a], 32);
    for (std::size_t at = 0; at < stream.size(); at += 60001) {  // not a multiple of 4: values straddle packets
      std::vector<std::string> buffers(3);
      buffers[a] = stream.substr(at, 60001);
      packets += data_packet(buffers);
    }
  }
  const std::string prototype = "<cartesianX type=\"Float\" precision=\"single\"/><cartesianY type=\"Float\" "
                                "precision=\"single\"/><cartesianZ type=\"Float\" precision=\"single\"/>";
  const PointCloud r = read_e57(write_file("steps.e57", assemble({packets}, xml_file(scan_xml("s", 0, n, prototype)))));
  ASSERT_EQ(r.size(), n);
  for (std::size_t i = 0; i < n; i += 997) {
    const double v = static_cast<float>(i % 1000) * 0.01f;
    ASSERT_LT((world(r, i) - Eigen::Vector3d(v, v + 1, v + 2)).norm(), 1e-5) << i;
  }
}

TEST_F(E57IoTest, NestedPrototypeFieldsKeepTheirBytestreamOrder) {
  // Bytestreams follow the prototype depth-first: colour (3 Integer streams inside a Structure) comes first.
  const std::vector<double> x = {1, 2, 3}, y = {4, 5, 6}, z = {7, 8, 9.5};
  const std::vector<std::uint64_t> colour = {255, 0, 128};
  const std::string prototype =
      "<colour type=\"Structure\"><r type=\"Integer\" minimum=\"0\" maximum=\"255\"/>"
      "<g type=\"Integer\" minimum=\"0\" maximum=\"255\"/><b type=\"Integer\" minimum=\"0\" maximum=\"255\"/></colour>"
      "<label type=\"String\"/>"
      "<cartesianX type=\"Float\" precision=\"double\"/><cartesianY type=\"Float\"/><cartesianZ type=\"Float\"/>"
      "<intensity type=\"Integer\" minimum=\"0\" maximum=\"4095\"/>";
  const std::string packet = data_packet({pack(colour, 8), pack(colour, 8), pack(colour, 8), std::string("\2ab\2cd\0", 7),
                                          pack(doubles(x), 64), pack(doubles(y), 64), pack(doubles(z), 64),
                                          pack({0, 4095, 1000}, 12)});
  const std::string pose =
      "      <pose type=\"Structure\"><rotation type=\"Structure\"><w type=\"Float\">0.7071067811865476</w>"
      "<x type=\"Float\">0</x><y type=\"Float\">0</y><z type=\"Float\">0.7071067811865476</z></rotation>"
      "<translation type=\"Structure\"><x type=\"Float\">100</x><y type=\"Float\">0</y><z type=\"Float\">-1</z>"
      "</translation></pose>\n";
  const std::string p = write_file("nested.e57", assemble({packet}, xml_file(scan_xml("n", 0, 3, prototype, pose))));
  const PointCloud r = read_e57(p);
  ASSERT_EQ(r.size(), 3u);
  // 90 degrees about z: (x, y, z) -> (-y, x, z), then + (100, 0, -1). No intensityLimits: the Integer's range.
  EXPECT_LT((world(r, 2) - Eigen::Vector3d(94, 3, 8.5)).norm(), 1e-6);
  ASSERT_TRUE(r.has_intensity());
  EXPECT_FLOAT_EQ(r.intensity[1], 1.0f);
  EXPECT_NEAR(r.intensity[2], 1000.0 / 4095.0, 1e-7);
}

TEST_F(E57IoTest, BadXmlAndBadStructureAreClearErrors) {
  const std::vector<double> v = {1, 2};
  const std::string packet = data_packet({pack(doubles(v), 64), pack(doubles(v), 64), pack(doubles(v), 64)});
  const std::string xyz = "<cartesianX type=\"Float\"/><cartesianY type=\"Float\"/><cartesianZ type=\"Float\"/>";
  std::string deep = xyz;
  for (int d = 0; d < 9; ++d) deep = "<s type=\"Structure\">" + deep + "</s>";
  const struct {
    const char* name;
    std::string xml;
    const char* needle;
  } cases[] = {
      {"unclosed.e57", "<e57Root type=\"Structure\"><data3D type=\"Vector\">", "bad XML section"},
      {"noroot.e57", "<root/>", "no e57Root"},
      {"noscans.e57", xml_file(""), "no scans"},
      {"nopoints.e57", xml_file("<vectorChild type=\"Structure\"/>"), "scan 0: has no 'points' CompressedVector"},
      {"count.e57", replaced(xml_file(scan_xml("c", 0, 2, xyz)), "recordCount=\"2\"", "recordCount=\"-2\""), "recordCount is not a count"},
      {"nocoords.e57", xml_file(scan_xml("n", 0, 2, "<cartesianX type=\"Float\"/>")), "neither cartesianX/Y/Z nor spherical"},
      {"precision.e57", xml_file(scan_xml("p", 0, 2, "<cartesianX type=\"Float\" precision=\"half\"/><cartesianY type=\"Float\"/><cartesianZ type=\"Float\"/>")), "prototype field 0 precision is neither single nor double"},
      {"string.e57", xml_file(scan_xml("s", 0, 2, "<cartesianX type=\"String\"/><cartesianY type=\"Float\"/><cartesianZ type=\"Float\"/>")), "cartesianX is a String"},
      {"minmax.e57", xml_file(scan_xml("m", 0, 2, "<cartesianX type=\"Integer\" minimum=\"5\" maximum=\"1\"/><cartesianY type=\"Float\"/><cartesianZ type=\"Float\"/>")), "minimum is above its maximum"},
      {"scale.e57", xml_file(scan_xml("z", 0, 2, "<cartesianX type=\"ScaledInteger\" minimum=\"0\" maximum=\"9\" scale=\"0\"/><cartesianY type=\"Float\"/><cartesianZ type=\"Float\"/>")), "scale is 0"},
      {"deep.e57", xml_file(scan_xml("d", 0, 2, deep)), "nested deeper than 8"},
      {"codec.e57", replaced(xml_file(scan_xml("k", 0, 2, xyz)), "<codecs type=\"Vector\" allowHeterogeneousChildren=\"1\"/>", "<codecs type=\"Vector\"><vectorChild type=\"Structure\"><zipCodec type=\"Structure\"/></vectorChild></codecs>"), "codec other than bitPackCodec"},
      {"pose.e57", xml_file(scan_xml("q", 0, 2, xyz, "<pose type=\"Structure\"><rotation type=\"Structure\"><w type=\"Float\">0</w><x type=\"Float\">0</x><y type=\"Float\">0</y><z type=\"Float\">0</z></rotation></pose>")), "zero quaternion"},
      {"posetext.e57", xml_file(scan_xml("t", 0, 2, xyz, "<pose type=\"Structure\"><translation type=\"Structure\"><x type=\"Float\">east</x><y type=\"Float\">0</y><z type=\"Float\">0</z></translation></pose>")), "pose translation x is not a number"},
      {"streams.e57", xml_file(scan_xml("b", 0, 2, xyz + "<intensity type=\"Float\"/>")), "data packet with 3 bytestreams for a prototype of 4 fields"},
      {"short.e57", xml_file(scan_xml("r", 0, 3, xyz)), "truncated"},
      {"shared.e57", xml_file(scan_xml("a", 0, 2, xyz) + scan_xml("b", 0, 2, xyz)),
       "scan 1's binary section overlaps the one of scan 0"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string p = write_file(c.name, assemble({packet}, c.xml));
    expect_error([&] { read_e57(p); }, ErrorCode::kInvalidArgument, p, c.needle);
  }
  const std::string outside = replaced(xml_file(scan_xml("o", 0, 2, xyz)), "@OFFSET0@", "1021");  // in page 0's CRC
  expect_error([&] { read_e57(write_file("crcoffset.e57", assemble({packet}, outside))); }, ErrorCode::kInvalidArgument,
               "crcoffset.e57", "fileOffset is not an offset inside the file");
}

// Errors never quote the file's text (file_text_in_errors_test.cpp for the other formats): a marker in every XML
// attribute or value a reader refuses, and in the scans' names, which errors refer to by index.
TEST_F(E57IoTest, ErrorsNeverQuoteTheXml) {
  const std::string marker = "SECRET-7f3a";
  const std::vector<double> v = {1, 2};
  const std::string packet = data_packet({pack(doubles(v), 64), pack(doubles(v), 64), pack(doubles(v), 64)});
  const std::string xyz = "<cartesianX type=\"Float\"/><cartesianY type=\"Float\"/><cartesianZ type=\"Float\"/>";
  const std::string yz = "<cartesianY type=\"Float\"/><cartesianZ type=\"Float\"/>";
  auto translation_x = [&](const std::string& x) {
    return "<pose type=\"Structure\"><translation type=\"Structure\">" + x +
           "<y type=\"Float\">0</y><z type=\"Float\">0</z></translation></pose>";
  };
  const std::string named = xml_file(scan_xml(marker, 0, 2, xyz));
  const std::string cases[] = {
      replaced(named, "recordCount=\"2\"", "recordCount=\"" + marker + "\""),
      replaced(named, "@OFFSET0@", marker),
      xml_file(scan_xml(marker, 0, 2, "<" + marker + " type=\"" + marker + "\"/>" + yz)),
      xml_file(scan_xml(marker, 0, 2, "<" + marker + " type=\"Float\" precision=\"" + marker + "\"/>" + xyz)),
      xml_file(scan_xml(marker, 0, 2, "<cartesianX type=\"Integer\" minimum=\"" + marker + "\"/>" + yz)),
      xml_file(scan_xml(marker, 0, 2, "<cartesianX type=\"Integer\" maximum=\"" + marker + "\"/>" + yz)),
      xml_file(scan_xml(marker, 0, 2, "<cartesianX type=\"ScaledInteger\" scale=\"" + marker + "\"/>" + yz)),
      xml_file(scan_xml(marker, 0, 2, "<cartesianX type=\"ScaledInteger\" offset=\"" + marker + "\"/>" + yz)),
      xml_file(scan_xml(marker, 0, 2, xyz, translation_x("<x type=\"Float\">" + marker + "</x>"))),
      xml_file(scan_xml(marker, 0, 2, xyz, translation_x("<x type=\"Integer\">" + marker + "</x>"))),
      xml_file(scan_xml(marker, 0, 2, xyz, translation_x("<x type=\"" + marker + "\">1</x>"))),
      xml_file(scan_xml(marker, 0, 2, xyz, translation_x("<x type=\"ScaledInteger\" scale=\"" + marker + "\">1</x>"))),
      xml_file(scan_xml(marker, 0, 3, xyz)),  // truncated: the scan by its index
      xml_file(scan_xml(marker, 0, 2, xyz) + scan_xml(marker, 0, 2, xyz)),  // overlapping scans
  };
  int n = 0;
  for (const std::string& xml : cases) {
    SCOPED_TRACE(n);
    const std::string p = write_file("marker" + std::to_string(n++) + ".e57", assemble({packet}, xml));
    try {
      read_e57(p);
      ADD_FAILURE() << "no error";
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).find(marker), std::string::npos) << e.what();
    }
  }
  // A scan asked for by a name none has: the request's name is quoted, the file's are not listed.
  ReadOptions by_name;
  by_name.scan_name = "Station 1";
  const std::string p = write_file("named.e57", assemble({packet}, named));
  try {
    read_e57(p, by_name);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).find(marker), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'Station 1'"), std::string::npos) << e.what();
  }
}

TEST_F(E57IoTest, BadPacketsAreClearErrors) {
  const std::vector<double> v = {1, 2};
  const std::string xyz = "<cartesianX type=\"Float\"/><cartesianY type=\"Float\"/><cartesianZ type=\"Float\"/>";
  const std::string xml = xml_file(scan_xml("p", 0, 2, xyz));
  const std::string good = data_packet({pack(doubles(v), 64), pack(doubles(v), 64), pack(doubles(v), 64)});
  std::string unknown = good, odd = good, long_buffer = good;
  unknown[0] = '\7';
  odd[2] = static_cast<char>(odd[2] - 2);  // length not a multiple of 4
  long_buffer[6] = static_cast<char>(200);  // first bytestream claims 200 bytes
  const struct {
    const char* name;
    std::string packets;
    const char* needle;
  } cases[] = {
      {"type.e57", unknown, "unknown packet type 7"},
      {"odd.e57", odd, "invalid length"},
      {"buffer.e57", long_buffer, "bytestream 0 passes the packet's end"},
      {"onlyindex.e57", index_packet(), "truncated: the section ends after 0 of 2 records"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string p = write_file(c.name, assemble({c.packets}, xml));
    expect_error([&] { read_e57(p); }, ErrorCode::kInvalidArgument, p, c.needle);
  }
  // An Integer 0–2 takes 2 bits, which can also hold 3: out of range, so corrupt.
  const std::string state = "<cartesianInvalidState type=\"Integer\" minimum=\"0\" maximum=\"2\"/>";
  const std::string with_state = data_packet({pack(doubles(v), 64), pack(doubles(v), 64), pack(doubles(v), 64), pack({0, 3}, 2)});
  const std::string p = write_file("range.e57", assemble({with_state}, xml_file(scan_xml("r", 0, 2, xyz + state))));
  expect_error([&] { read_e57(p); }, ErrorCode::kInvalidArgument, p, "outside its field's [minimum, maximum]");
}

TEST_F(E57IoTest, HugeRecordCountsAreRefusedInstantly) {
  const std::string xyz = "<cartesianX type=\"Float\"/><cartesianY type=\"Float\"/><cartesianZ type=\"Float\"/>";
  const std::vector<double> v = {1};
  const std::string packet = data_packet({pack(doubles(v), 64), pack(doubles(v), 64), pack(doubles(v), 64)});
  const std::string p = write_file("huge.e57", assemble({packet}, xml_file(scan_xml("h", 0, 1000000000000ull, xyz))));
  EXPECT_LE(fs::file_size(p), 2048u);
  const auto t0 = std::chrono::steady_clock::now();
  expect_error([&] { read_e57(p); }, ErrorCode::kInvalidArgument, p, "truncated: recordCount 1000000000000");
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::milliseconds(100));
  // Every coordinate constant: a record count would not be backed by any data.
  const std::string constant = "<cartesianX type=\"Integer\" minimum=\"1\" maximum=\"1\"/>"
                               "<cartesianY type=\"Integer\" minimum=\"1\" maximum=\"1\"/>"
                               "<cartesianZ type=\"Integer\" minimum=\"1\" maximum=\"1\"/>";
  const std::string c = write_file("constant.e57", assemble({data_packet({"", "", ""})}, xml_file(scan_xml("c", 0, 1000000000000ull, constant))));
  expect_error([&] { read_e57(c); }, ErrorCode::kInvalidArgument, c, "every coordinate field is constant");
}

// ------------------------------------------------------------------------------------------------
// Damage
// ------------------------------------------------------------------------------------------------

TEST_F(E57IoTest, EveryFlippedByteIsDataLossOrAClearErrorNeverACrash) {
  E57Scan scan = make_scan("damaged", scan_cloud(Eigen::Vector3d::Zero(), 200, 9, true));
  E57WriteOptions options;
  options.coordinates = E57Coordinates::kCartesianScaledInteger;
  write_e57(path("good.e57"), {scan}, options);
  const std::string good = read_bytes(path("good.e57"));
  ASSERT_GE(good.size(), 3 * 1024u);
  EXPECT_EQ(read_e57_bytes(good, "good.e57").size(), 200u);
  std::size_t data_loss = 0;
  for (std::size_t at = 0; at < good.size(); ++at) {
    std::string bad = good;
    bad[at] = static_cast<char>(bad[at] ^ 0x10);
    try {
      read_e57_bytes(bad, "bad.e57");
      ADD_FAILURE() << "byte " << at << ": damage not detected";
    } catch (const Error& e) {
      const std::string msg = e.what();
      ASSERT_EQ(msg.rfind("bad.e57: ", 0), 0u) << msg;
      if (e.code() == ErrorCode::kDataLoss) {
        ++data_loss;
        ASSERT_NE(msg.find("CRC-32C mismatch in page " + std::to_string(at / 1024)), std::string::npos) << msg;
      } else {
        // Bytes the reader checks before any CRC: the signature and the declared length.
        ASSERT_EQ(e.code(), ErrorCode::kInvalidArgument) << msg;
        ASSERT_TRUE(at < 8 || (at >= 16 && at < 24)) << at << ": " << msg;
      }
    }
  }
  EXPECT_GE(data_loss, good.size() - 16);
}

TEST_F(E57IoTest, TruncatedFilesAreClearErrors) {
  write_e57(path("t.e57"), {make_scan("t", scan_cloud(Eigen::Vector3d::Zero(), 400, 11, false))});
  const std::string good = read_bytes(path("t.e57"));
  for (std::size_t keep : {std::size_t{0}, std::size_t{5}, std::size_t{100}, std::size_t{1023}, std::size_t{1024},
                           good.size() / 2, good.size() - 1024, good.size() - 1}) {
    SCOPED_TRACE(keep);
    const std::string name = "cut" + std::to_string(keep) + ".e57";
    expect_error([&] { read_e57_bytes(std::string_view(good).substr(0, keep), name); }, ErrorCode::kInvalidArgument, name,
                 keep == 0 ? "empty" : keep < 8 ? "wrong magic" : "truncated");
  }
}

}  // namespace
}  // namespace k4reg
