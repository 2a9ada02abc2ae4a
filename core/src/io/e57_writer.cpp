// E57 writer: one CompressedVector section per scan (bitPackCodec data packets), the XML last. The layout is
// planned before writing — every packet's size follows from the record count and the fields' bit widths — so
// the file header and the XML (which hold offsets) are known up front and the file is written front to back.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "e57_bitpack.h"
#include "e57_format.h"
#include "e57_pages.h"
#include "io_common.h"
#include "k4reg/io/e57_io.h"
#include "k4reg/util/error.h"

namespace k4reg {
namespace {

using e57::FieldCodec;
using io_detail::fail_io;

struct FieldWriter {
  std::string name;  // prototype element
  FieldCodec codec;
  std::function<std::uint64_t(std::size_t)> raw;  // the packed bits of record i
};

// What a scan's section will hold: its fields and the records of each data packet.
struct SectionPlan {
  std::vector<FieldWriter> fields;
  std::size_t records = 0, records_per_packet = 0;
  std::uint64_t logical_start = 0, length = 0;
  double intensity_min = 0.0, intensity_max = 0.0;
  bool integer_intensity = false;
};

// Bytes of a field's stream once `records` of `total` records are packed (the last packet completes the byte).
std::uint64_t stream_bytes(std::uint64_t records, std::uint64_t total, unsigned bits) {
  const std::uint64_t stream_bits = records * bits;
  return records == total ? (stream_bits + 7) / 8 : stream_bits / 8;
}

std::size_t packet_length(const SectionPlan& plan, std::size_t first, std::size_t last) {
  std::size_t length = e57::kDataPacketHeaderSize + 2 * plan.fields.size();
  for (const FieldWriter& f : plan.fields)
    length += stream_bytes(last, plan.records, f.codec.bits()) - stream_bytes(first, plan.records, f.codec.bits());
  return (length + 3) / 4 * 4;
}

FieldWriter float_field(std::string name, bool single, std::function<double(std::size_t)> value) {
  FieldWriter f{std::move(name), {}, {}};
  f.codec.single_precision = single;
  if (single)
    f.raw = [value](std::size_t i) { return std::uint64_t{std::bit_cast<std::uint32_t>(static_cast<float>(value(i)))}; };
  else
    f.raw = [value](std::size_t i) { return std::bit_cast<std::uint64_t>(value(i)); };
  return f;
}

FieldWriter integer_field(std::string name, FieldCodec::Type type, std::int64_t minimum, std::int64_t maximum,
                          std::function<std::int64_t(std::size_t)> value) {
  FieldWriter f{std::move(name), {}, {}};
  f.codec.type = type;
  f.codec.minimum = minimum;
  f.codec.maximum = maximum;
  f.raw = [value, minimum](std::size_t i) {
    return static_cast<std::uint64_t>(value(i)) - static_cast<std::uint64_t>(minimum);
  };
  return f;
}

void coordinate_fields(const E57Scan& scan, const E57WriteOptions& options, std::vector<FieldWriter>& fields) {
  const PointCloud& cloud = scan.cloud;
  switch (options.coordinates) {
    case E57Coordinates::kCartesianDouble:
    case E57Coordinates::kCartesianSingle:
      for (int a = 0; a < 3; ++a)
        fields.push_back(float_field(std::string("cartesian") + "XYZ"[a],
                                     options.coordinates == E57Coordinates::kCartesianSingle,
                                     [&cloud, a](std::size_t i) { return io_detail::world_point(cloud, i)[a]; }));
      return;
    case E57Coordinates::kCartesianScaledInteger:
      for (int a = 0; a < 3; ++a) {
        const double scale = options.resolution_m;
        auto integer = [&cloud, a, scale](std::size_t i) {
          return static_cast<std::int64_t>(std::llround(cloud.points[i][a] / scale));
        };
        std::int64_t lo = integer(0), hi = lo;
        for (std::size_t i = 1; i < cloud.size(); ++i) {
          lo = std::min(lo, integer(i));
          hi = std::max(hi, integer(i));
        }
        if (hi == lo) ++hi;  // at least one bit, so that a record count is backed by data
        fields.push_back(integer_field(std::string("cartesian") + "XYZ"[a], FieldCodec::Type::kScaledInteger, lo, hi, integer));
        fields.back().codec.scale = scale;
        fields.back().codec.offset = cloud.origin_m[a];
      }
      return;
    case E57Coordinates::kSphericalDouble: {
      auto range = [&cloud](std::size_t i) { return io_detail::world_point(cloud, i).norm(); };
      auto azimuth = [&cloud](std::size_t i) {
        const Eigen::Vector3d p = io_detail::world_point(cloud, i);
        return std::atan2(p.y(), p.x());
      };
      auto elevation = [&cloud](std::size_t i) {
        const Eigen::Vector3d p = io_detail::world_point(cloud, i);
        const double r = p.norm();
        return r > 0.0 ? std::asin(std::clamp(p.z() / r, -1.0, 1.0)) : 0.0;
      };
      fields.push_back(float_field("sphericalRange", false, range));
      fields.push_back(float_field("sphericalAzimuth", false, azimuth));
      fields.push_back(float_field("sphericalElevation", false, elevation));
      return;
    }
  }
}

SectionPlan plan_section(const E57Scan& scan, const E57WriteOptions& options) {
  SectionPlan plan;
  const PointCloud& cloud = scan.cloud;
  plan.records = cloud.size();
  coordinate_fields(scan, options, plan.fields);
  if (cloud.has_intensity()) {
    const auto [lo, hi] = std::minmax_element(cloud.intensity.begin(), cloud.intensity.end());
    plan.intensity_min = *lo;
    plan.intensity_max = *hi;
    if (options.intensity_bits == 0) {
      plan.fields.push_back(float_field("intensity", true, [&cloud](std::size_t i) { return cloud.intensity[i]; }));
    } else {
      plan.integer_intensity = true;
      const std::int64_t top = (std::int64_t{1} << options.intensity_bits) - 1;
      const double lo_value = *lo, span = *hi - *lo;
      plan.fields.push_back(integer_field("intensity", FieldCodec::Type::kInteger, 0, top, [&cloud, lo_value, span, top](std::size_t i) {
        return span > 0.0 ? std::llround((cloud.intensity[i] - lo_value) / span * static_cast<double>(top)) : std::int64_t{0};
      }));
      plan.intensity_min = 0.0;
      plan.intensity_max = static_cast<double>(top);
    }
  }
  if (!scan.invalid_state.empty()) {
    const bool spherical = options.coordinates == E57Coordinates::kSphericalDouble;
    plan.fields.push_back(integer_field(spherical ? "sphericalInvalidState" : "cartesianInvalidState",
                                        FieldCodec::Type::kInteger, 0, 2,
                                        [&scan](std::size_t i) { return std::int64_t{scan.invalid_state[i]}; }));
  }
  std::uint64_t bits_per_record = 0;
  for (const FieldWriter& f : plan.fields) bits_per_record += f.codec.bits();
  // Room for the stream data once the header, the length table, padding and a partial byte per stream are taken.
  const std::size_t budget_bits = 8 * (e57::kMaxPacketSize - e57::kDataPacketHeaderSize - 3 * plan.fields.size() - 3);
  plan.records_per_packet = static_cast<std::size_t>(std::max<std::uint64_t>(1, budget_bits / bits_per_record));
  plan.length = e57::kSectionHeaderSize;
  for (std::size_t first = 0; first < plan.records; first += plan.records_per_packet)
    plan.length += packet_length(plan, first, std::min(plan.records, first + plan.records_per_packet));
  return plan;
}

void check_scans(const std::vector<E57Scan>& scans, const E57WriteOptions& options, const std::string& path) {
  if (scans.empty()) fail_io(ErrorCode::kInvalidArgument, path, "cannot write an E57 file without scans");
  if (options.intensity_bits < 0 || options.intensity_bits > 32)
    fail_io(ErrorCode::kInvalidArgument, path, "intensity_bits must be 0 (Float) or 1–32");
  if (!(options.resolution_m > 0.0) || !std::isfinite(options.resolution_m))
    fail_io(ErrorCode::kInvalidArgument, path, "the resolution must be positive");
  for (std::size_t s = 0; s < scans.size(); ++s) {
    const E57Scan& scan = scans[s];
    const std::string which = "cannot write scan " + std::to_string(s) + ": ";
    io_detail::check_cloud_for_writing(scan.cloud, path);
    if (scan.cloud.empty()) fail_io(ErrorCode::kInvalidArgument, path, which + "no points");
    if (!scan.invalid_state.empty() && scan.invalid_state.size() != scan.cloud.size())
      fail_io(ErrorCode::kInvalidArgument, path, which + "invalid_state needs one value per point");
    for (std::uint8_t state : scan.invalid_state)
      if (state > 2) fail_io(ErrorCode::kInvalidArgument, path, which + "an invalid state above 2");
    if (!scan.pose.matrix().allFinite()) fail_io(ErrorCode::kInvalidArgument, path, which + "the pose is not finite");
    if (options.coordinates == E57Coordinates::kCartesianScaledInteger) {
      double extent = 0.0;
      for (const Eigen::Vector3f& p : scan.cloud.points) extent = std::max(extent, static_cast<double>(p.cwiseAbs().maxCoeff()));
      if (extent / options.resolution_m > 4e18)
        fail_io(ErrorCode::kInvalidArgument, path, which + "the extent does not fit 64-bit integers at this resolution");
    }
  }
}

// ---- XML ----

std::string cdata(std::string_view text) {
  std::string out = "<![CDATA[";
  for (std::size_t i = 0; i < text.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (text.substr(i, 3) == "]]>") {
      out += "]]]]><![CDATA[>";  // "]]>" cannot appear inside one CDATA section
      i += 2;
    } else {
      out += c < 0x20 && c != '\t' && c != '\n' && c != '\r' ? '?' : static_cast<char>(c);  // not allowed in XML 1.0
    }
  }
  return out + "]]>";
}

std::string number(double value) {
  std::string out;
  io_detail::append_number(out, value);
  return out;
}

std::string float_element(const char* tag, double value) {
  return std::string("<") + tag + " type=\"Float\">" + number(value) + "</" + tag + ">";
}

std::string guid(std::mt19937_64& random) {
  char text[40];
  const std::uint64_t a = random(), b = random();
  std::snprintf(text, sizeof text, "{%08X-%04X-%04X-%04X-%012llX}", static_cast<unsigned>(a >> 32),
                static_cast<unsigned>((a >> 16) & 0xFFFF), static_cast<unsigned>(a & 0xFFFF),
                static_cast<unsigned>(b >> 48), static_cast<unsigned long long>(b & 0xFFFFFFFFFFFFull));
  return text;
}

std::string prototype_field(const FieldWriter& f) {
  const FieldCodec& c = f.codec;
  switch (c.type) {
    case FieldCodec::Type::kFloat:
      return "<" + f.name + " type=\"Float\" precision=\"" + (c.single_precision ? "single" : "double") + "\"/>";
    case FieldCodec::Type::kInteger:
      return "<" + f.name + " type=\"Integer\" minimum=\"" + std::to_string(c.minimum) + "\" maximum=\"" +
             std::to_string(c.maximum) + "\"/>";
    case FieldCodec::Type::kScaledInteger:
      return "<" + f.name + " type=\"ScaledInteger\" minimum=\"" + std::to_string(c.minimum) + "\" maximum=\"" +
             std::to_string(c.maximum) + "\" scale=\"" + number(c.scale) + "\" offset=\"" + number(c.offset) + "\"/>";
    case FieldCodec::Type::kString:
      break;
  }
  return {};
}

std::string scan_xml(const E57Scan& scan, const SectionPlan& plan, std::mt19937_64& random) {
  const Eigen::Quaterniond q(scan.pose.linear());
  const Eigen::Vector3d t = scan.pose.translation();
  std::string xml = "<vectorChild type=\"Structure\">";
  xml += "<guid type=\"String\">" + cdata(guid(random)) + "</guid>";
  xml += "<name type=\"String\">" + cdata(scan.name) + "</name>";
  xml += "<pose type=\"Structure\"><rotation type=\"Structure\">" + float_element("w", q.w()) +
         float_element("x", q.x()) + float_element("y", q.y()) + float_element("z", q.z()) +
         "</rotation><translation type=\"Structure\">" + float_element("x", t.x()) + float_element("y", t.y()) +
         float_element("z", t.z()) + "</translation></pose>";
  if (scan.cloud.has_intensity()) {
    const char* type = plan.integer_intensity ? "Integer" : "Float";
    auto limit = [&](const char* tag, double value) {
      return std::string("<") + tag + " type=\"" + type + "\">" +
             (plan.integer_intensity ? std::to_string(std::llround(value)) : number(value)) + "</" + tag + ">";
    };
    xml += "<intensityLimits type=\"Structure\">" + limit("intensityMinimum", plan.intensity_min) +
           limit("intensityMaximum", plan.intensity_max) + "</intensityLimits>";
  }
  xml += "<points type=\"CompressedVector\" fileOffset=\"" + std::to_string(e57::logical_to_physical(plan.logical_start)) +
         "\" recordCount=\"" + std::to_string(plan.records) + "\"><prototype type=\"Structure\">";
  for (const FieldWriter& f : plan.fields) xml += prototype_field(f);
  xml += "</prototype><codecs type=\"Vector\" allowHeterogeneousChildren=\"1\"></codecs></points></vectorChild>";
  return xml;
}

// ---- binary ----

void write_section(e57::PagedWriter& pages, const SectionPlan& plan, const std::string& path) {
  const std::uint64_t data_logical = plan.logical_start + e57::kSectionHeaderSize;
  std::string header;
  header += static_cast<char>(e57::kCompressedVectorSection);
  header.append(7, '\0');
  io_detail::append_le<std::uint64_t>(header, plan.length);
  io_detail::append_le<std::uint64_t>(header, e57::logical_to_physical(data_logical));
  io_detail::append_le<std::uint64_t>(header, 0);  // no index packets
  pages.write(header);

  std::vector<e57::BitPacker> packers(plan.fields.size());
  std::string packet;
  for (std::size_t first = 0; first < plan.records; first += plan.records_per_packet) {
    const std::size_t last = std::min(plan.records, first + plan.records_per_packet);
    const std::size_t length = packet_length(plan, first, last);
    packet.clear();
    packet += static_cast<char>(e57::kDataPacket);
    packet += '\0';
    io_detail::append_le<std::uint16_t>(packet, static_cast<std::uint16_t>(length - 1));
    io_detail::append_le<std::uint16_t>(packet, static_cast<std::uint16_t>(plan.fields.size()));
    for (std::size_t f = 0; f < plan.fields.size(); ++f) {
      const FieldWriter& field = plan.fields[f];
      const unsigned bits = field.codec.bits();
      for (std::size_t i = first; i < last; ++i) packers[f].put(field.raw(i), bits);
      if (last == plan.records) packers[f].finish();
      io_detail::append_le<std::uint16_t>(packet, static_cast<std::uint16_t>(packers[f].bytes().size()));
    }
    for (e57::BitPacker& packer : packers) {
      packet += packer.bytes();
      packer.bytes().clear();
    }
    packet.resize((packet.size() + 3) / 4 * 4, '\0');
    if (packet.size() != length)
      fail_io(ErrorCode::kInternal, path, "E57 packet of " + std::to_string(packet.size()) + " bytes, planned " +
                                              std::to_string(length));
    pages.write(packet);
  }
}

}  // namespace

void write_e57(const std::string& path, const std::vector<E57Scan>& scans, const E57WriteOptions& options) {
  check_scans(scans, options, path);
  std::vector<SectionPlan> plans;
  std::uint64_t logical = e57::kFileHeaderSize;
  for (const E57Scan& scan : scans) {
    plans.push_back(plan_section(scan, options));
    plans.back().logical_start = logical;
    logical += plans.back().length;
  }

  std::mt19937_64 random(std::random_device{}());
  std::string xml = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
                    "<e57Root type=\"Structure\" xmlns=\"http://www.astm.org/COMMIT/E57/2010-e57-v1.0\">"
                    "<formatName type=\"String\">" + cdata("ASTM E57 3D Imaging Data File") + "</formatName>"
                    "<guid type=\"String\">" + cdata(guid(random)) + "</guid>"
                    "<versionMajor type=\"Integer\">1</versionMajor><versionMinor type=\"Integer\">0</versionMinor>"
                    "<e57LibraryVersion type=\"String\">" + cdata("k4reg write_e57") + "</e57LibraryVersion>"
                    "<coordinateMetadata type=\"String\"></coordinateMetadata>"
                    "<data3D type=\"Vector\" allowHeterogeneousChildren=\"1\">";
  for (std::size_t s = 0; s < scans.size(); ++s) xml += scan_xml(scans[s], plans[s], random);
  xml += "</data3D><images2D type=\"Vector\" allowHeterogeneousChildren=\"1\"></images2D></e57Root>\n";

  const std::uint64_t xml_logical = logical, end_logical = xml_logical + xml.size();
  const std::uint64_t pages_total = (end_logical + e57::kPageData - 1) / e57::kPageData;
  std::string header(e57::kSignature, 8);
  io_detail::append_le<std::uint32_t>(header, 1);  // major version
  io_detail::append_le<std::uint32_t>(header, 0);  // minor version
  io_detail::append_le<std::uint64_t>(header, pages_total * e57::kPageSize);
  io_detail::append_le<std::uint64_t>(header, e57::logical_to_physical(xml_logical));
  io_detail::append_le<std::uint64_t>(header, xml.size());
  io_detail::append_le<std::uint64_t>(header, e57::kPageSize);

  io_detail::OutputFile out(path);
  e57::PagedWriter pages(out);
  pages.write(header);
  for (const SectionPlan& plan : plans) write_section(pages, plan, path);
  if (pages.logical_position() != xml_logical)
    fail_io(ErrorCode::kInternal, path, "E57 sections took " + std::to_string(pages.logical_position()) +
                                            " bytes, planned " + std::to_string(xml_logical));
  pages.write(xml);
  pages.finish();
  out.commit();
}

}  // namespace k4reg
