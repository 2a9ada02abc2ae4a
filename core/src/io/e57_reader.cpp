// E57 reader: file header and pages (e57_pages), the XML section (pugixml), CompressedVector sections decoded
// with the bitPackCodec (e57_bitpack). Rules are documented in e57_io.h.
#include <pugixml.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "e57_bitpack.h"
#include "e57_format.h"
#include "e57_pages.h"
#include "declared_counts.h"
#include "io_common.h"
#include "k4reg/io/e57_io.h"
#include "k4reg/util/error.h"

namespace k4reg {
namespace {

using e57::FieldCodec;
using io_detail::fail_io;
using io_detail::load_le;

constexpr int kMaxPrototypeDepth = 8;
constexpr std::size_t kMaxPrototypeFields = 1024;

// One /data3D entry as the XML describes it.
struct ScanLayout {
  std::string label;  // "scan 2" for messages (never its name: that is the file's text)
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  std::uint64_t section_logical = 0, section_end = 0, data_logical = 0;  // the binary section, logical offsets
  std::uint64_t record_count = 0;
  std::vector<FieldCodec> fields;  // one per bytestream, in bytestream order (depth-first over the prototype)
  bool spherical = false;
  int coordinate[3] = {-1, -1, -1};  // x/y/z, or range/azimuth/elevation
  int invalid_state = -1, intensity = -1;
  bool normalise_intensity = false;
  double intensity_min = 0.0, intensity_max = 1.0;
};

std::string_view trimmed(std::string_view s) {
  const std::size_t first = s.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return {};
  return s.substr(first, s.find_last_not_of(" \t\r\n") - first + 1);
}

// An element's text: all its character data and CDATA sections (a string holding "]]>" is split over two CDATA
// sections), trimmed.
std::string text_of(pugi::xml_node node) {
  std::string text;
  for (const pugi::xml_node child : node.children())
    if (child.type() == pugi::node_pcdata || child.type() == pugi::node_cdata) text += child.value();
  return std::string(trimmed(text));
}

bool parse_int64(std::string_view token, std::int64_t& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const auto result = std::from_chars(token.data(), token.data() + token.size(), value);
  return !token.empty() && result.ec == std::errc() && result.ptr == token.data() + token.size();
}

class XmlScanParser {
 public:
  XmlScanParser(const std::string& file_name, e57::PagedReader& pages) : file_(file_name), pages_(pages) {}

  ScanLayout parse(pugi::xml_node node, std::size_t index) {
    ScanLayout scan;
    scan.label = "scan " + std::to_string(index);
    label_ = scan.label;
    if (const pugi::xml_node pose = node.child("pose")) parse_pose(pose, scan.pose);
    const pugi::xml_node points = node.child("points");
    if (!points || std::string_view(points.attribute("type").value()) != "CompressedVector")
      fail("has no 'points' CompressedVector");
    std::uint64_t file_offset = 0;
    if (!io_detail::parse_uint64(trimmed(points.attribute("fileOffset").value()), file_offset) ||
        !e57::physical_to_logical(file_offset, scan.section_logical) ||
        scan.section_logical >= pages_.logical_size())
      fail("points fileOffset is not an offset inside the file");
    section_header(scan);
    if (!io_detail::parse_uint64(trimmed(points.attribute("recordCount").value()), scan.record_count))
      fail("points recordCount is not a count");
    const pugi::xml_node prototype = points.child("prototype");
    if (!prototype) fail("points have no prototype");
    std::vector<std::string> names;
    flatten(prototype, 0, scan.fields, names);
    for (const pugi::xml_node codec : points.child("codecs").children())
      if (!codec.child("bitPackCodec")) fail("uses a codec other than bitPackCodec, which is not supported");
    assign_fields(scan, names);
    if (scan.intensity >= 0) intensity_range(node, scan);
    return scan;
  }

 private:
  [[noreturn]] void fail(const std::string& message) const {
    fail_io(ErrorCode::kInvalidArgument, file_, label_ + ": " + message);
  }

  // The value of a Float, Integer or ScaledInteger element (an empty element is 0, as in the standard).
  double number(pugi::xml_node node, const std::string& what) const {
    if (!node) fail("lacks " + what);
    const std::string_view type = node.attribute("type").value();
    const std::string text = text_of(node);
    double value = 0.0;
    if (type == "Float") {
      if (!text.empty() && !io_detail::parse_double(text, value)) fail(what + " is not a number");
    } else if (type == "Integer" || type == "ScaledInteger") {
      std::int64_t integer = 0;
      if (!text.empty() && !parse_int64(text, integer)) fail(what + " is not an integer");
      value = static_cast<double>(integer);
      if (type == "ScaledInteger")
        value = value * attribute(node, what, "scale", 1.0) + attribute(node, what, "offset", 0.0);
    } else {
      fail(what + " is not a Float, Integer or ScaledInteger");
    }
    if (!std::isfinite(value)) fail(what + " is not finite");
    return value;
  }

  // `what` names the node in errors: its element name may be the file's text.
  double attribute(pugi::xml_node node, const std::string& what, const char* key, double fallback) const {
    const pugi::xml_attribute a = node.attribute(key);
    if (!a) return fallback;
    double value;
    if (!io_detail::parse_double(trimmed(a.value()), value) || !std::isfinite(value))
      fail(what + " attribute " + key + " is not a finite number");
    return value;
  }

  std::int64_t attribute(pugi::xml_node node, const std::string& what, const char* key, std::int64_t fallback) const {
    const pugi::xml_attribute a = node.attribute(key);
    if (!a) return fallback;
    std::int64_t value;
    if (!parse_int64(trimmed(a.value()), value))
      fail(what + " attribute " + key + " is not a 64-bit integer");
    return value;
  }

  void parse_pose(pugi::xml_node pose, Eigen::Isometry3d& out) const {
    Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
    if (const pugi::xml_node r = pose.child("rotation"))
      q = Eigen::Quaterniond(number(r.child("w"), "pose rotation w"), number(r.child("x"), "pose rotation x"),
                             number(r.child("y"), "pose rotation y"), number(r.child("z"), "pose rotation z"));
    if (!(q.norm() > 1e-9)) fail("pose rotation is not a rotation (zero quaternion)");
    Eigen::Vector3d t = Eigen::Vector3d::Zero();
    if (const pugi::xml_node tr = pose.child("translation"))
      t = Eigen::Vector3d(number(tr.child("x"), "pose translation x"), number(tr.child("y"), "pose translation y"),
                          number(tr.child("z"), "pose translation z"));
    out = Eigen::Isometry3d::Identity();
    out.linear() = q.normalized().toRotationMatrix();
    out.translation() = t;
  }

  // what: "prototype field 3", the node by its position.
  FieldCodec codec(pugi::xml_node node, const std::string& what) const {
    const std::string_view type = node.attribute("type").value();
    FieldCodec c;
    if (type == "Float") {
      const std::string_view precision = node.attribute("precision").value();
      if (precision != "" && precision != "single" && precision != "double")
        fail(what + " precision is neither single nor double");
      c.single_precision = precision == "single";
      return c;
    }
    if (type == "String") {
      c.type = FieldCodec::Type::kString;
      return c;
    }
    if (type != "Integer" && type != "ScaledInteger")
      fail(what + " has a type other than Float, Integer, ScaledInteger, String, Structure or Vector");
    c.type = type == "Integer" ? FieldCodec::Type::kInteger : FieldCodec::Type::kScaledInteger;
    c.minimum = attribute(node, what, "minimum", std::numeric_limits<std::int64_t>::min());
    c.maximum = attribute(node, what, "maximum", std::numeric_limits<std::int64_t>::max());
    if (c.minimum > c.maximum) fail(what + " minimum is above its maximum");
    if (c.type == FieldCodec::Type::kScaledInteger) {
      c.scale = attribute(node, what, "scale", 1.0);
      c.offset = attribute(node, what, "offset", 0.0);
      if (c.scale == 0.0) fail(what + " scale is 0");
    }
    return c;
  }

  // Terminal fields in depth-first order (the bytestream order); names only for the prototype's own children.
  void flatten(pugi::xml_node node, int depth, std::vector<FieldCodec>& fields, std::vector<std::string>& names) const {
    for (const pugi::xml_node child : node.children()) {
      if (child.type() != pugi::node_element) continue;
      const std::string_view type = child.attribute("type").value();
      if (type == "Structure" || type == "Vector") {
        if (depth + 1 >= kMaxPrototypeDepth) fail("prototype nested deeper than " + std::to_string(kMaxPrototypeDepth));
        flatten(child, depth + 1, fields, names);
        continue;
      }
      if (fields.size() >= kMaxPrototypeFields)
        fail("prototype has more than " + std::to_string(kMaxPrototypeFields) + " fields");
      fields.push_back(codec(child, "prototype field " + std::to_string(fields.size())));
      names.push_back(depth == 0 ? child.name() : "");
    }
  }

  void assign_fields(ScanLayout& scan, const std::vector<std::string>& names) const {
    auto find = [&](const char* field) {
      const auto it = std::find(names.begin(), names.end(), field);
      return it == names.end() ? -1 : static_cast<int>(it - names.begin());
    };
    const int cartesian[3] = {find("cartesianX"), find("cartesianY"), find("cartesianZ")};
    const int spherical[3] = {find("sphericalRange"), find("sphericalAzimuth"), find("sphericalElevation")};
    scan.spherical = std::min({cartesian[0], cartesian[1], cartesian[2]}) < 0;
    const int* chosen = scan.spherical ? spherical : cartesian;
    if (std::min({chosen[0], chosen[1], chosen[2]}) < 0)
      fail("the prototype has neither cartesianX/Y/Z nor sphericalRange/Azimuth/Elevation");
    std::copy(chosen, chosen + 3, scan.coordinate);
    scan.invalid_state = find(scan.spherical ? "sphericalInvalidState" : "cartesianInvalidState");
    scan.intensity = find("intensity");
    bool any_varying = false;
    for (int f : {chosen[0], chosen[1], chosen[2], scan.invalid_state, scan.intensity}) {
      if (f < 0) continue;
      if (scan.fields[f].type == FieldCodec::Type::kString) fail("field " + names[f] + " is a String, not a number");
      any_varying |= scan.fields[f].bits() > 0 && f != scan.invalid_state && f != scan.intensity;
    }
    if (!any_varying && scan.record_count > 1) fail("every coordinate field is constant (0 bits): all points coincide");
  }

  void intensity_range(pugi::xml_node node, ScanLayout& scan) const {
    const FieldCodec& field = scan.fields[scan.intensity];
    if (const pugi::xml_node limits = node.child("intensityLimits")) {
      scan.intensity_min = number(limits.child("intensityMinimum"), "intensityLimits intensityMinimum");
      scan.intensity_max = number(limits.child("intensityMaximum"), "intensityLimits intensityMaximum");
    } else if (field.type != FieldCodec::Type::kFloat) {
      scan.intensity_min = field.value(0);
      scan.intensity_max = field.value(static_cast<std::uint64_t>(field.maximum) - static_cast<std::uint64_t>(field.minimum));
    } else {
      return;  // a Float without limits: taken as is
    }
    if (scan.intensity_min > scan.intensity_max) std::swap(scan.intensity_min, scan.intensity_max);
    scan.normalise_intensity = scan.intensity_max > scan.intensity_min;
  }

  // The CompressedVector section header at the scan's fileOffset: where the section ends and its data starts.
  void section_header(ScanLayout& scan) {
    const std::string header = pages_.read(scan.section_logical, e57::kSectionHeaderSize);
    if (static_cast<unsigned char>(header[0]) != e57::kCompressedVectorSection)
      fail("no CompressedVector section at its fileOffset");
    const std::uint64_t length = load_le<std::uint64_t>(header.data() + 8);
    if (length < e57::kSectionHeaderSize || length > pages_.logical_size() - scan.section_logical)
      fail("section length " + std::to_string(length) + " passes the end of the file");
    scan.section_end = scan.section_logical + length;
    if (!e57::physical_to_logical(load_le<std::uint64_t>(header.data() + 16), scan.data_logical) ||
        scan.data_logical < scan.section_logical + e57::kSectionHeaderSize || scan.data_logical >= scan.section_end)
      fail("the first data packet is not inside the section");
  }

  const std::string& file_;
  e57::PagedReader& pages_;
  std::string label_;
};

// Appends the valid points of one scan (and their intensity, if the scan has it) in the file's frame.
class ScanDecoder {
 public:
  ScanDecoder(const ScanLayout& scan, e57::PagedReader& pages, const std::string& name)
      : scan_(scan), pages_(pages), name_(name) {
    const int roles[kRoles] = {scan.coordinate[0], scan.coordinate[1], scan.coordinate[2], scan.invalid_state,
                               scan.intensity};
    for (int r = 0; r < kRoles; ++r) {
      const int f = roles[r];
      if (f < 0 || scan.fields[f].bits() == 0) continue;  // absent, or constant: value(0)
      for (std::size_t s = 0; s < streams_.size(); ++s)
        if (streams_[s].field == f) stream_of_role_[r] = static_cast<int>(s);
      if (stream_of_role_[r] >= 0) continue;
      stream_of_role_[r] = static_cast<int>(streams_.size());
      streams_.push_back(Stream{f, e57::BitUnpacker(scan.fields[f].bits()), {}, 0, 0});
    }
  }

  void decode(const ReadOptions& options, std::vector<Eigen::Vector3d>& points, std::vector<float>& intensity) {
    end_ = scan_.section_end;
    const std::uint64_t length = scan_.section_end - scan_.section_logical;
    std::uint64_t bits_per_record = 0;
    for (const Stream& s : streams_) bits_per_record += scan_.fields[s.field].bits();
    if (!io_detail::mul_fits(scan_.record_count, bits_per_record, 8 * length))
      fail("truncated: recordCount " + std::to_string(scan_.record_count) + " needs more than the " +
           std::to_string(length) + " bytes of its section");
    // Real scans take 3 bytes or more per record, so reserving a record per 3 section bytes (at most 8 bytes of
    // points per file byte) covers them; denser claims grow the vector only as records actually decode.
    points.reserve(points.size() + std::min<std::uint64_t>(scan_.record_count, length / 3));
    for (std::uint64_t pos = scan_.data_logical; emitted_ < scan_.record_count;) {
      if (pos + 4 > end_)
        fail("truncated: the section ends after " + std::to_string(emitted_) + " of " +
             std::to_string(scan_.record_count) + " records");
      pos += packet(pos);
      emit(options, points, intensity);
    }
  }

 private:
  struct Stream {
    int field;
    e57::BitUnpacker unpacker;
    std::vector<double> values;  // decoded, not yet emitted
    std::size_t head;
    std::uint64_t decoded;
  };

  [[noreturn]] void fail(const std::string& message) const {
    fail_io(ErrorCode::kInvalidArgument, name_, scan_.label + ": " + message);
  }

  // Reads the packet at `pos` (feeding a data packet's buffers to the streams) and returns its length.
  std::uint64_t packet(std::uint64_t pos) {
    char head[4];
    pages_.read(pos, 4, head);
    const unsigned type = static_cast<unsigned char>(head[0]);
    const std::size_t length = load_le<std::uint16_t>(head + 2) + std::size_t{1};
    if (length < 4 || length % 4 != 0) fail("packet of invalid length " + std::to_string(length));
    if (pos + length > end_) fail("packet at logical offset " + std::to_string(pos) + " passes the end of its section");
    if (type == e57::kIndexPacket || type == e57::kEmptyPacket) return length;
    if (type != e57::kDataPacket) fail("unknown packet type " + std::to_string(type));
    if (length < e57::kDataPacketHeaderSize) fail("data packet of " + std::to_string(length) + " bytes");
    pages_.read(pos, length, packet_);
    const std::size_t count = load_le<std::uint16_t>(packet_ + 4);
    if (count != scan_.fields.size())
      fail("data packet with " + std::to_string(count) + " bytestreams for a prototype of " +
           std::to_string(scan_.fields.size()) + " fields");
    std::size_t offset = e57::kDataPacketHeaderSize + 2 * count;
    if (offset > length) fail("data packet too short for its bytestream lengths");
    std::vector<std::string_view> buffers(count);
    for (std::size_t b = 0; b < count; ++b) {
      const std::size_t size = load_le<std::uint16_t>(packet_ + e57::kDataPacketHeaderSize + 2 * b);
      if (size > length - offset) fail("data packet bytestream " + std::to_string(b) + " passes the packet's end");
      buffers[b] = std::string_view(packet_ + offset, size);
      offset += size;
    }
    for (Stream& s : streams_) {
      const FieldCodec& codec = scan_.fields[s.field];
      const std::uint64_t range = static_cast<std::uint64_t>(codec.maximum) - static_cast<std::uint64_t>(codec.minimum);
      const bool integer = codec.type != FieldCodec::Type::kFloat;
      s.decoded += s.unpacker.unpack(buffers[s.field], scan_.record_count - s.decoded, [&](std::uint64_t raw) {
        if (integer && raw > range) fail("a value outside its field's [minimum, maximum]: corrupt data");
        s.values.push_back(codec.value(raw));
      });
    }
    return length;
  }

  // Record k (from the oldest not yet emitted) of a role's field.
  double value(int role, int field, std::size_t k) const {
    if (stream_of_role_[role] < 0) return scan_.fields[field].value(0);  // constant (0 bits)
    const Stream& s = streams_[stream_of_role_[role]];
    return s.values[s.head + k];
  }

  // Turns the records that every stream has decoded into points.
  void emit(const ReadOptions& options, std::vector<Eigen::Vector3d>& points, std::vector<float>& intensity) {
    std::uint64_t ready = scan_.record_count - emitted_;
    for (const Stream& s : streams_) ready = std::min<std::uint64_t>(ready, s.values.size() - s.head);
    for (std::size_t k = 0; k < ready; ++k) {
      if (scan_.invalid_state >= 0 && value(kInvalid, scan_.invalid_state, k) != 0.0) continue;
      const double a = value(0, scan_.coordinate[0], k), b = value(1, scan_.coordinate[1], k),
                   c = value(2, scan_.coordinate[2], k);
      // Spherical: range a, azimuth b, elevation c (radians).
      const Eigen::Vector3d p = scan_.spherical ? Eigen::Vector3d(a * std::cos(c) * std::cos(b),
                                                                  a * std::cos(c) * std::sin(b), a * std::sin(c))
                                                : Eigen::Vector3d(a, b, c);
      if (options.max_points != 0 && points.size() >= options.max_points)
        fail_io(ErrorCode::kResourceExhausted, name_, "more than " + std::to_string(options.max_points) + " points");
      points.push_back(options.apply_pose ? scan_.pose * p : p);
      if (scan_.intensity >= 0) {
        double v = value(kIntensity, scan_.intensity, k);
        if (scan_.normalise_intensity) v = (v - scan_.intensity_min) / (scan_.intensity_max - scan_.intensity_min);
        intensity.push_back(static_cast<float>(v));
      }
    }
    emitted_ += ready;
    for (Stream& s : streams_) {  // drop what was emitted; streams a packet ahead keep their surplus
      s.head += ready;
      if (s.head == s.values.size() || s.head > (std::size_t{1} << 16)) {
        s.values.erase(s.values.begin(), s.values.begin() + static_cast<std::ptrdiff_t>(s.head));
        s.head = 0;
      }
    }
  }

  // Roles 0–2 are the coordinates.
  static constexpr int kInvalid = 3, kIntensity = 4, kRoles = 5;

  const ScanLayout& scan_;
  e57::PagedReader& pages_;
  const std::string& name_;
  std::vector<Stream> streams_;
  int stream_of_role_[kRoles] = {-1, -1, -1, -1, -1};
  std::uint64_t end_ = 0, emitted_ = 0;
  char packet_[e57::kMaxPacketSize];
};

// An E57 file opened: its pages, its XML and the /data3D entries (at least one). Throws for a damaged file.
struct OpenedE57 {
  OpenedE57(std::string_view data, std::uint64_t page_count, const std::string& name) : pages(data, page_count, name) {}
  e57::PagedReader pages;
  pugi::xml_document document;
  std::vector<pugi::xml_node> entries;
};

std::unique_ptr<OpenedE57> open_e57(std::string_view data, const std::string& name) {
  if (data.empty()) fail_io(ErrorCode::kInvalidArgument, name, "empty file");
  if (data.substr(0, 8) != e57::kSignature)
    fail_io(ErrorCode::kInvalidArgument, name, "not an E57 file (wrong magic: no 'ASTM-E57')");
  if (data.size() < e57::kPageSize)
    fail_io(ErrorCode::kInvalidArgument, name,
            "truncated: " + std::to_string(data.size()) + " bytes, an E57 file has at least one 1024-byte page");
  const std::uint64_t declared = load_le<std::uint64_t>(data.data() + 16);
  if (declared == 0 || declared % e57::kPageSize != 0)
    fail_io(ErrorCode::kInvalidArgument, name,
            "declared length " + std::to_string(declared) + " is not a whole number of 1024-byte pages");
  if (declared > data.size())
    fail_io(ErrorCode::kInvalidArgument, name,
            "truncated: the header declares " + std::to_string(declared) + " bytes, the file has " +
                std::to_string(data.size()));
  auto opened = std::make_unique<OpenedE57>(data, declared / e57::kPageSize, name);
  e57::PagedReader& pages = opened->pages;
  const std::string header = pages.read(0, e57::kFileHeaderSize);  // checks page 0's CRC
  const std::uint32_t major = load_le<std::uint32_t>(header.data() + 8);
  const std::uint64_t page_size = load_le<std::uint64_t>(header.data() + 40);
  if (major != 1) fail_io(ErrorCode::kInvalidArgument, name, "unsupported E57 version " + std::to_string(major));
  if (page_size != e57::kPageSize)
    fail_io(ErrorCode::kInvalidArgument, name, "page size " + std::to_string(page_size) + " (only 1024 is defined)");
  std::uint64_t xml_logical = 0;
  const std::uint64_t xml_length = load_le<std::uint64_t>(header.data() + 32);
  if (!e57::physical_to_logical(load_le<std::uint64_t>(header.data() + 24), xml_logical) || xml_length == 0 ||
      xml_logical > pages.logical_size() || xml_length > pages.logical_size() - xml_logical)
    fail_io(ErrorCode::kInvalidArgument, name, "the XML section is not inside the file");
  const std::string xml = pages.read(xml_logical, static_cast<std::size_t>(xml_length));

  pugi::xml_document& document = opened->document;
  const pugi::xml_parse_result parsed = document.load_buffer(xml.data(), xml.size(), pugi::parse_default, pugi::encoding_utf8);
  if (!parsed)
    fail_io(ErrorCode::kInvalidArgument, name,
            std::string("bad XML section: ") + parsed.description() + " at byte " + std::to_string(parsed.offset));
  if (!document.child("e57Root")) fail_io(ErrorCode::kInvalidArgument, name, "the XML has no e57Root element");
  const pugi::xml_node data3d = document.child("e57Root").child("data3D");
  std::vector<pugi::xml_node>& entries = opened->entries;
  for (const pugi::xml_node child : data3d.children())
    if (child.type() == pugi::node_element) entries.push_back(child);
  if (entries.empty()) fail_io(ErrorCode::kInvalidArgument, name, "no scans (/data3D is empty)");

  return opened;
}

// The selected scans' layouts and their records, from the XML and the sections' headers: what the file holds before
// a record is decoded.
struct E57Plan {
  std::unique_ptr<OpenedE57> opened;
  std::vector<ScanLayout> scans;
  std::uint64_t records = 0;
};

// The header pass (declared_points stops here): the plan, its records checked against options.max_points where
// each is a point (records with an invalid state are none).
E57Plan plan_e57(std::string_view data, const std::string& name, const ReadOptions& options) {
  E57Plan plan;
  plan.opened = open_e57(data, name);
  const std::vector<pugi::xml_node>& entries = plan.opened->entries;
  std::vector<std::size_t> selected;
  if (options.scan_index && !options.scan_name.empty())
    fail_io(ErrorCode::kInvalidArgument, name, "select a scan by index or by name, not both");
  if (options.scan_index) {
    if (*options.scan_index >= entries.size())
      fail_io(ErrorCode::kInvalidArgument, name,
              "scan index " + std::to_string(*options.scan_index) + " does not exist: the file has " +
                  std::to_string(entries.size()) + " scan" + (entries.size() == 1 ? "" : "s") + " (0-based)");
    selected.push_back(*options.scan_index);
  } else if (!options.scan_name.empty()) {
    // The request's name may be quoted; the file's names are not listed: they are its text.
    for (std::size_t i = 0; i < entries.size(); ++i)
      if (text_of(entries[i].child("name")) == options.scan_name) selected.push_back(i);
    if (selected.empty())
      fail_io(ErrorCode::kInvalidArgument, name,
              "none of its " + std::to_string(entries.size()) + " scans is named '" + options.scan_name +
                  "'; select one by name or by index (0-based)");
    if (selected.size() > 1)
      fail_io(ErrorCode::kInvalidArgument, name,
              std::to_string(selected.size()) + " scans are named '" + options.scan_name + "'; select one by index");
  } else {
    for (std::size_t i = 0; i < entries.size(); ++i) selected.push_back(i);
  }

  XmlScanParser parser(name, plan.opened->pages);
  bool every_record_is_a_point = true;
  for (std::size_t i : selected) {
    plan.scans.push_back(parser.parse(entries[i], i));
    plan.records += plan.scans.back().record_count;
    every_record_is_a_point &= plan.scans.back().invalid_state < 0;
  }
  if (every_record_is_a_point) io_detail::check_point_budget(plan.records, options, name);
  return plan;
}

}  // namespace

std::uint64_t io_detail::declared_e57_points(std::string_view data, const std::string& name,
                                             const ReadOptions& options) {
  return plan_e57(data, name, options).records;
}

PointCloud read_e57_bytes(std::string_view data, const std::string& name, const ReadOptions& options) {
  const E57Plan plan = plan_e57(data, name, options);
  e57::PagedReader& pages = plan.opened->pages;
  const std::vector<ScanLayout>& scans = plan.scans;
  // Each scan's records must come from its own bytes: scans sharing a section would multiply a small file.
  std::vector<const ScanLayout*> by_offset;
  for (const ScanLayout& scan : scans) by_offset.push_back(&scan);
  std::sort(by_offset.begin(), by_offset.end(),
            [](const ScanLayout* a, const ScanLayout* b) { return a->section_logical < b->section_logical; });
  for (std::size_t i = 1; i < by_offset.size(); ++i)
    if (by_offset[i]->section_logical < by_offset[i - 1]->section_end)
      fail_io(ErrorCode::kInvalidArgument, name,
              by_offset[i]->label + "'s binary section overlaps the one of " + by_offset[i - 1]->label);

  std::vector<Eigen::Vector3d> points;
  std::vector<float> intensity;
  bool all_have_intensity = true;
  for (const ScanLayout& scan : scans) {
    const std::size_t first_point = points.size(), first_intensity = intensity.size();
    auto decoder = std::make_unique<ScanDecoder>(scan, pages, name);  // holds a 64 KiB packet buffer
    decoder->decode(options, points, intensity);
    bool varies = false;
    for (std::size_t i = first_intensity; i < intensity.size() && !varies; ++i) varies = intensity[i] != intensity[first_intensity];
    all_have_intensity &= points.size() == first_point || (scan.intensity >= 0 && varies);
  }
  if (!all_have_intensity) intensity.clear();
  PointCloud cloud = io_detail::finish_cloud(std::move(points), std::move(intensity), name);
  // A scan's pose places its own frame, the scanner's, in the file's; merged scans have no one scanner.
  if (scans.size() == 1)
    cloud.scanner_m = options.apply_pose ? Eigen::Vector3d(scans.front().pose.translation()) : Eigen::Vector3d::Zero();
  return cloud;
}

std::size_t count_e57_scans(std::string_view data, const std::string& name) { return open_e57(data, name)->entries.size(); }

PointCloud read_e57(const std::string& path, const ReadOptions& options) {
  io_detail::MappedFile file(path);
  return read_e57_bytes(file.bytes(), path, options);
}

}  // namespace k4reg
