// PLY reader/writer. The binary vertex block is decoded in place from the memory-mapped file with a
// per-property offset table (no per-point stream I/O), in parallel blocks.
#include "k4reg/io/ply_io.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "declared_counts.h"
#include "io_common.h"
#include "k4reg/util/error.h"

namespace k4reg {
namespace {

using io_detail::fail_io;

enum class PlyType { kInt8, kUInt8, kInt16, kUInt16, kInt32, kUInt32, kFloat32, kFloat64 };
enum class PlyFormat { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

std::size_t type_size(PlyType type) {
  switch (type) {
    case PlyType::kInt8:
    case PlyType::kUInt8:
      return 1;
    case PlyType::kInt16:
    case PlyType::kUInt16:
      return 2;
    case PlyType::kInt32:
    case PlyType::kUInt32:
    case PlyType::kFloat32:
      return 4;
    case PlyType::kFloat64:
      return 8;
  }
  return 0;
}

bool parse_type(std::string_view s, PlyType& type) {
  struct Entry {
    const char* name;
    PlyType type;
  };
  static constexpr Entry kTypes[] = {
      {"char", PlyType::kInt8},      {"int8", PlyType::kInt8},       {"uchar", PlyType::kUInt8},
      {"uint8", PlyType::kUInt8},    {"short", PlyType::kInt16},     {"int16", PlyType::kInt16},
      {"ushort", PlyType::kUInt16},  {"uint16", PlyType::kUInt16},   {"int", PlyType::kInt32},
      {"int32", PlyType::kInt32},    {"uint", PlyType::kUInt32},     {"uint32", PlyType::kUInt32},
      {"float", PlyType::kFloat32},  {"float32", PlyType::kFloat32}, {"double", PlyType::kFloat64},
      {"float64", PlyType::kFloat64},
  };
  for (const Entry& e : kTypes) {
    if (s == e.name) {
      type = e.type;
      return true;
    }
  }
  return false;
}

struct PlyProperty {
  std::string name;
  bool is_list = false;
  PlyType type = PlyType::kFloat32;        // scalar type, or list item type
  PlyType count_type = PlyType::kUInt8;    // list count type
  std::size_t offset = 0;                  // byte offset in a fixed-size binary record (scalars only)
  std::size_t header_line = 0;
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
  bool has_list = false;
  std::size_t stride = 0;        // bytes of a binary record when !has_list
  std::size_t min_bytes = 0;     // smallest possible binary record (list counts of 0)
  std::size_t min_tokens = 0;    // smallest possible ASCII record
  std::size_t header_line = 0;
};

// Errors name an element or a property by the header line declaring it, never by its name: that is the file's text.
std::string element_at(std::size_t header_line) {
  return "the element of header line " + std::to_string(header_line);
}
std::string property_at(std::size_t header_line) {
  return "the property of header line " + std::to_string(header_line);
}

struct PlyHeader {
  PlyFormat format = PlyFormat::kAscii;
  std::vector<PlyElement> elements;
  std::size_t body_offset = 0;
  std::size_t header_lines = 0;
};

std::vector<std::string_view> split_ws(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  auto ws = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; };
  while (i < line.size() && out.size() <= io_detail::kMaxTokensPerLine) {  // longer lines are malformed anyway
    while (i < line.size() && ws(line[i])) ++i;
    if (i >= line.size()) break;
    std::size_t start = i;
    while (i < line.size() && !ws(line[i])) ++i;
    out.push_back(line.substr(start, i - start));
  }
  return out;
}

PlyHeader parse_header(std::string_view data, const std::string& name) {
  if (data.empty()) fail_io(ErrorCode::kInvalidArgument, name, "empty file");
  io_detail::LineReader lines(data);
  std::string_view line;
  lines.next(line);
  if (line != "ply")
    fail_io(ErrorCode::kInvalidArgument, name,
            "not a PLY file: wrong magic (the first line is not 'ply')");
  PlyHeader header;
  bool have_format = false, have_end = false;
  while (lines.next(line)) {
    const std::size_t ln = lines.line_number();
    auto where = [ln] { return "header line " + std::to_string(ln) + ": "; };  // built only for an error
    std::vector<std::string_view> tok = split_ws(line);
    if (tok.empty()) continue;
    const std::string_view key = tok[0];
    if (key == "end_header") {
      have_end = true;
      break;
    }
    if (key == "comment" || key == "obj_info") continue;
    if (key == "format") {
      if (tok.size() != 3) fail_io(ErrorCode::kInvalidArgument, name, where() + "malformed format line");
      if (tok[1] == "ascii") {
        header.format = PlyFormat::kAscii;
      } else if (tok[1] == "binary_little_endian") {
        header.format = PlyFormat::kBinaryLittleEndian;
      } else if (tok[1] == "binary_big_endian") {
        header.format = PlyFormat::kBinaryBigEndian;
      } else {
        fail_io(ErrorCode::kInvalidArgument, name,
                where() + "unknown PLY format (ascii, binary_little_endian or binary_big_endian are read)");
      }
      if (tok[2] != "1.0" && tok[2] != "1")
        fail_io(ErrorCode::kInvalidArgument, name, where() + "unsupported PLY version (1.0 is read)");
      have_format = true;
    } else if (key == "element") {
      if (tok.size() != 3) fail_io(ErrorCode::kInvalidArgument, name, where() + "malformed element line");
      PlyElement element;
      element.name = std::string(tok[1]);
      if (!io_detail::parse_uint64(tok[2], element.count))
        fail_io(ErrorCode::kInvalidArgument, name,
                where() + "the element count is not a non-negative integer");
      element.header_line = ln;
      if (header.elements.size() == io_detail::kMaxHeaderEntries)
        fail_io(ErrorCode::kInvalidArgument, name,
                where() + "more than " + std::to_string(io_detail::kMaxHeaderEntries) + " elements");
      header.elements.push_back(std::move(element));
    } else if (key == "property") {
      if (header.elements.empty())
        fail_io(ErrorCode::kInvalidArgument, name, where() + "property before any element");
      PlyElement& element = header.elements.back();
      if (element.properties.size() == io_detail::kMaxHeaderEntries)
        fail_io(ErrorCode::kInvalidArgument, name,
                where() + element_at(element.header_line) + " has more than " +
                    std::to_string(io_detail::kMaxHeaderEntries) + " properties");
      PlyProperty prop;
      prop.header_line = ln;
      if (tok.size() >= 2 && tok[1] == "list") {
        if (tok.size() != 5) fail_io(ErrorCode::kInvalidArgument, name, where() + "malformed list property");
        if (!parse_type(tok[2], prop.count_type) || !parse_type(tok[3], prop.type))
          fail_io(ErrorCode::kInvalidArgument, name, where() + "unknown property type in list");
        if (prop.count_type == PlyType::kFloat32 || prop.count_type == PlyType::kFloat64)
          fail_io(ErrorCode::kInvalidArgument, name, where() + "list count type must be an integer type");
        prop.is_list = true;
        prop.name = std::string(tok[4]);
        element.has_list = true;
        element.min_bytes += type_size(prop.count_type);
      } else {
        if (tok.size() != 3) fail_io(ErrorCode::kInvalidArgument, name, where() + "malformed property line");
        if (!parse_type(tok[1], prop.type))
          fail_io(ErrorCode::kInvalidArgument, name, where() + "unknown property type");
        prop.name = std::string(tok[2]);
        prop.offset = element.stride;
        element.stride += type_size(prop.type);
        element.min_bytes += type_size(prop.type);
      }
      element.min_tokens += 1;
      element.properties.push_back(std::move(prop));
    } else {
      fail_io(ErrorCode::kInvalidArgument, name, where() + "unknown header keyword");
    }
  }
  if (!have_end) fail_io(ErrorCode::kInvalidArgument, name, "malformed header: no end_header line");
  if (!have_format) fail_io(ErrorCode::kInvalidArgument, name, "malformed header: no format line");
  header.body_offset = lines.position();
  header.header_lines = lines.line_number();
  return header;
}

// ---- binary helpers ----

template <typename T>
inline T load(const char* p, bool swap) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return swap ? io_detail::byteswap_value(v) : v;
}

inline double load_as_double(const char* p, PlyType type, bool swap) {
  switch (type) {
    case PlyType::kInt8:
      return load<std::int8_t>(p, false);
    case PlyType::kUInt8:
      return load<std::uint8_t>(p, false);
    case PlyType::kInt16:
      return load<std::int16_t>(p, swap);
    case PlyType::kUInt16:
      return load<std::uint16_t>(p, swap);
    case PlyType::kInt32:
      return load<std::int32_t>(p, swap);
    case PlyType::kUInt32:
      return load<std::uint32_t>(p, swap);
    case PlyType::kFloat32:
      return load<float>(p, swap);
    case PlyType::kFloat64:
      return load<double>(p, swap);
  }
  return 0.0;
}

// Reads a list count; negative counts are refused.
std::uint64_t load_count(const char* p, PlyType type, bool swap, const std::string& name, std::size_t byte) {
  std::int64_t v = 0;
  switch (type) {
    case PlyType::kInt8:
      v = load<std::int8_t>(p, false);
      break;
    case PlyType::kUInt8:
      v = load<std::uint8_t>(p, false);
      break;
    case PlyType::kInt16:
      v = load<std::int16_t>(p, swap);
      break;
    case PlyType::kUInt16:
      v = load<std::uint16_t>(p, swap);
      break;
    case PlyType::kInt32:
      v = load<std::int32_t>(p, swap);
      break;
    case PlyType::kUInt32:
      v = load<std::uint32_t>(p, swap);
      break;
    default:
      break;
  }
  if (v < 0) fail_io(ErrorCode::kInvalidArgument, name, "negative list count at byte " + std::to_string(byte));
  return static_cast<std::uint64_t>(v);
}

// Decodes one channel of `count` fixed-size records into out[i * out_stride].
template <typename T, typename Out>
void decode_channel_typed(const char* base, std::size_t stride, std::size_t offset, std::size_t begin,
                          std::size_t end, bool swap, Out* out, std::size_t out_stride) {
  const char* p = base + begin * stride + offset;
  Out* o = out + begin * out_stride;
  if (swap && sizeof(T) > 1) {
    for (std::size_t i = begin; i < end; ++i, p += stride, o += out_stride) {
      T v;
      std::memcpy(&v, p, sizeof(T));
      *o = static_cast<Out>(io_detail::byteswap_value(v));
    }
  } else {
    for (std::size_t i = begin; i < end; ++i, p += stride, o += out_stride) {
      T v;
      std::memcpy(&v, p, sizeof(T));
      *o = static_cast<Out>(v);
    }
  }
}

template <typename Out>
void decode_channel(PlyType type, const char* base, std::size_t stride, std::size_t offset, std::size_t begin,
                    std::size_t end, bool swap, Out* out, std::size_t out_stride) {
  switch (type) {
    case PlyType::kInt8:
      return decode_channel_typed<std::int8_t>(base, stride, offset, begin, end, swap, out, out_stride);
    case PlyType::kUInt8:
      return decode_channel_typed<std::uint8_t>(base, stride, offset, begin, end, swap, out, out_stride);
    case PlyType::kInt16:
      return decode_channel_typed<std::int16_t>(base, stride, offset, begin, end, swap, out, out_stride);
    case PlyType::kUInt16:
      return decode_channel_typed<std::uint16_t>(base, stride, offset, begin, end, swap, out, out_stride);
    case PlyType::kInt32:
      return decode_channel_typed<std::int32_t>(base, stride, offset, begin, end, swap, out, out_stride);
    case PlyType::kUInt32:
      return decode_channel_typed<std::uint32_t>(base, stride, offset, begin, end, swap, out, out_stride);
    case PlyType::kFloat32:
      return decode_channel_typed<float>(base, stride, offset, begin, end, swap, out, out_stride);
    case PlyType::kFloat64:
      return decode_channel_typed<double>(base, stride, offset, begin, end, swap, out, out_stride);
  }
}

constexpr std::array<const char*, 6> kIntensityNames = {"intensity",        "scalar_Intensity", "reflectance",
                                                        "scalar_intensity", "Intensity",        "i"};

// Indices of x, y, z and intensity (-1 if absent) among the vertex properties.
struct VertexLayout {
  std::array<int, 3> xyz = {-1, -1, -1};
  int intensity = -1;
};

VertexLayout find_vertex_layout(const PlyElement& vertex, const std::string& name) {
  VertexLayout layout;
  const char* axes[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    for (std::size_t p = 0; p < vertex.properties.size(); ++p) {
      if (vertex.properties[p].name == axes[a] && !vertex.properties[p].is_list) {
        layout.xyz[a] = static_cast<int>(p);
        break;
      }
    }
    if (layout.xyz[a] < 0)
      fail_io(ErrorCode::kInvalidArgument, name,
              std::string("malformed header: element vertex has no scalar property '") + axes[a] + "'");
  }
  for (const char* candidate : kIntensityNames) {
    for (std::size_t p = 0; p < vertex.properties.size() && layout.intensity < 0; ++p)
      if (vertex.properties[p].name == candidate && !vertex.properties[p].is_list)
        layout.intensity = static_cast<int>(p);
    if (layout.intensity >= 0) break;
  }
  return layout;
}

[[noreturn]] void fail_truncated(const std::string& name, const std::string& what) {
  fail_io(ErrorCode::kInvalidArgument, name, "truncated: " + what);
}

// Skips one binary element with list properties record by record; returns the new position.
std::size_t skip_binary_list_element(std::string_view data, std::size_t pos, const PlyElement& element, bool swap,
                                     const std::string& name) {
  for (std::uint64_t r = 0; r < element.count; ++r) {
    for (const PlyProperty& prop : element.properties) {
      if (!prop.is_list) {
        if (data.size() - pos < type_size(prop.type))
          fail_truncated(name, element_at(element.header_line) + ", record " + std::to_string(r) + " of " +
                                   std::to_string(element.count) + " ends past the end of the file (byte " +
                                   std::to_string(data.size()) + ")");
        pos += type_size(prop.type);
        continue;
      }
      const std::size_t cs = type_size(prop.count_type);
      if (data.size() - pos < cs)
        fail_truncated(name, element_at(element.header_line) + ", record " + std::to_string(r) + " of " +
                                 std::to_string(element.count) + " ends past the end of the file (byte " +
                                 std::to_string(data.size()) + ")");
      std::uint64_t n = load_count(data.data() + pos, prop.count_type, swap, name, pos);
      pos += cs;
      if (!io_detail::mul_fits(n, type_size(prop.type), data.size() - pos))
        fail_truncated(name, element_at(element.header_line) + ", record " + std::to_string(r) + ": " +
                                 property_at(prop.header_line) + ", a list of " + std::to_string(n) +
                                 " items, runs past the end of the file (byte " + std::to_string(data.size()) + ")");
      pos += n * type_size(prop.type);
    }
  }
  return pos;
}

bool swapped(const PlyHeader& header) {
  return (header.format == PlyFormat::kBinaryBigEndian) != (std::endian::native == std::endian::big);
}

// Where a binary file's vertex records start (past the elements before them), once the data can hold them.
std::size_t binary_vertex_offset(std::string_view data, const PlyHeader& header, std::size_t vertex_index,
                                 const std::string& name) {
  const bool swap = swapped(header);
  std::size_t pos = header.body_offset;
  // Elements before the vertex element.
  for (std::size_t e = 0; e < vertex_index; ++e) {
    const PlyElement& element = header.elements[e];
    if (element.properties.empty() || element.count == 0) continue;
    if (!io_detail::mul_fits(element.count, element.min_bytes, data.size() - pos))
      fail_truncated(name, "header line " + std::to_string(element.header_line) + " declares " +
                               std::to_string(element.count) + " elements of at least " +
                               std::to_string(element.min_bytes) + " bytes, only " + std::to_string(data.size() - pos) +
                               " bytes follow (byte " + std::to_string(pos) + ")");
    if (!element.has_list) {
      pos += element.count * element.stride;
    } else {
      pos = skip_binary_list_element(data, pos, element, swap, name);
    }
  }
  const PlyElement& vertex = header.elements[vertex_index];
  const std::size_t remaining = data.size() - pos;
  const std::uint64_t n = vertex.count;
  if (!io_detail::mul_fits(n, vertex.min_bytes, remaining)) {
    fail_truncated(name, "header says " + std::to_string(n) + " vertices, data holds " +
                             std::to_string(vertex.min_bytes ? remaining / vertex.min_bytes : 0) + " (" +
                             std::to_string(vertex.min_bytes) + " bytes per vertex from byte " + std::to_string(pos) +
                             ", file is " + std::to_string(data.size()) + " bytes)");
  }
  return pos;
}

// What the header tells before a point is decoded: the vertex element, its layout, where its binary records start.
struct PlyPlan {
  PlyHeader header;
  std::size_t vertex_index = 0;
  VertexLayout layout;
  std::size_t binary_vertex_offset = 0;
  const PlyElement& vertex() const { return header.elements[vertex_index]; }
};

PointCloud read_binary(std::string_view data, const PlyPlan& plan, const std::string& name) {
  const bool swap = swapped(plan.header);
  const VertexLayout& layout = plan.layout;
  const PlyElement& vertex = plan.vertex();
  const std::uint64_t n = vertex.count;
  std::size_t pos = plan.binary_vertex_offset;
  std::vector<Eigen::Vector3d> points(n);
  std::vector<float> intensity(layout.intensity >= 0 ? n : 0);
  double* xyz_out = points.empty() ? nullptr : points.data()->data();
  static_assert(sizeof(Eigen::Vector3d) == 3 * sizeof(double));

  if (!vertex.has_list) {
    const char* base = data.data() + pos;
    const std::size_t stride = vertex.stride;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1 << 16), [&](const tbb::blocked_range<std::size_t>& r) {
      for (int a = 0; a < 3; ++a) {
        const PlyProperty& prop = vertex.properties[layout.xyz[a]];
        decode_channel(prop.type, base, stride, prop.offset, r.begin(), r.end(), swap, xyz_out + a, 3);
      }
      if (layout.intensity >= 0) {
        const PlyProperty& prop = vertex.properties[layout.intensity];
        decode_channel(prop.type, base, stride, prop.offset, r.begin(), r.end(), swap, intensity.data(), 1);
      }
    });
  } else {
    // Vertex records with list properties (unusual): walk record by record.
    for (std::uint64_t i = 0; i < n; ++i) {
      for (std::size_t p = 0; p < vertex.properties.size(); ++p) {
        const PlyProperty& prop = vertex.properties[p];
        if (prop.is_list) {
          const std::size_t cs = type_size(prop.count_type);
          if (data.size() - pos < cs)
            fail_truncated(name, "header says " + std::to_string(n) + " vertices, data holds " + std::to_string(i));
          std::uint64_t count = load_count(data.data() + pos, prop.count_type, swap, name, pos);
          pos += cs;
          if (!io_detail::mul_fits(count, type_size(prop.type), data.size() - pos))
            fail_truncated(name, "header says " + std::to_string(n) + " vertices, data holds " + std::to_string(i));
          pos += count * type_size(prop.type);
          continue;
        }
        const std::size_t size = type_size(prop.type);
        if (data.size() - pos < size)
          fail_truncated(name, "header says " + std::to_string(n) + " vertices, data holds " + std::to_string(i));
        const double v = load_as_double(data.data() + pos, prop.type, swap);
        for (int a = 0; a < 3; ++a)
          if (layout.xyz[a] == static_cast<int>(p)) points[i][a] = v;
        if (layout.intensity == static_cast<int>(p)) intensity[i] = static_cast<float>(v);
        pos += size;
      }
    }
  }
  return io_detail::finish_cloud(std::move(points), std::move(intensity), name);
}

// Refuses a vertex count an ASCII body cannot hold: every value takes at least one character and one separator.
void check_ascii_vertex_count(std::string_view data, const PlyHeader& header, const PlyElement& vertex,
                              const std::string& name) {
  const std::uint64_t n = vertex.count;
  const std::size_t remaining = data.size() - header.body_offset + 1;
  if (!io_detail::mul_fits(n, 2 * vertex.min_tokens, remaining))
    fail_truncated(name, "header says " + std::to_string(n) + " vertices of " + std::to_string(vertex.min_tokens) +
                             " values, but the " + std::to_string(remaining - 1) +
                             "-byte body can hold at most " + std::to_string(remaining / (2 * vertex.min_tokens)));
}

PointCloud read_ascii(std::string_view data, const PlyPlan& plan, const std::string& name) {
  const PlyHeader& header = plan.header;
  const std::size_t vertex_index = plan.vertex_index;
  const VertexLayout& layout = plan.layout;
  io_detail::TokenReader tokens(data.substr(header.body_offset), header.header_lines + 1);
  std::string_view token;
  auto end_of_file = [&](const PlyElement& element, std::uint64_t record) {
    fail_truncated(name, "header line " + std::to_string(element.header_line) + " declares " +
                             std::to_string(element.count) + " elements, data ends after " + std::to_string(record) +
                             " (line " + std::to_string(tokens.line()) + ")");
  };
  for (std::size_t e = 0; e < vertex_index; ++e) {
    const PlyElement& element = header.elements[e];
    if (element.properties.empty()) continue;
    for (std::uint64_t r = 0; r < element.count; ++r) {
      for (const PlyProperty& prop : element.properties) {
        if (!tokens.next(token)) end_of_file(element, r);
        if (!prop.is_list) continue;
        std::uint64_t count;
        if (!io_detail::parse_uint64(token, count))
          fail_io(ErrorCode::kInvalidArgument, name,
                  "line " + std::to_string(tokens.line()) + ": a list count of " + element_at(element.header_line) +
                      " is not a non-negative integer");
        for (std::uint64_t k = 0; k < count; ++k)
          if (!tokens.next(token)) end_of_file(element, r);
      }
    }
  }
  const PlyElement& vertex = plan.vertex();
  const std::uint64_t n = vertex.count;
  std::vector<Eigen::Vector3d> points(n);
  std::vector<float> intensity(layout.intensity >= 0 ? n : 0);
  for (std::uint64_t i = 0; i < n; ++i) {
    for (std::size_t p = 0; p < vertex.properties.size(); ++p) {
      const PlyProperty& prop = vertex.properties[p];
      if (!tokens.next(token))
        fail_truncated(name, "header says " + std::to_string(n) + " vertices, data holds " + std::to_string(i) +
                                 " (file ends at line " + std::to_string(tokens.line()) + ")");
      if (prop.is_list) {
        std::uint64_t count;
        if (!io_detail::parse_uint64(token, count))
          fail_io(ErrorCode::kInvalidArgument, name,
                  "line " + std::to_string(tokens.line()) + ": vertex " + std::to_string(i) + ": the list count of " +
                      property_at(prop.header_line) + " is not a non-negative integer");
        for (std::uint64_t k = 0; k < count; ++k)
          if (!tokens.next(token))
            fail_truncated(name, "header says " + std::to_string(n) + " vertices, data holds " + std::to_string(i));
        continue;
      }
      double v;
      if (!io_detail::parse_double(token, v))
        fail_io(ErrorCode::kInvalidArgument, name,
                "line " + std::to_string(tokens.line()) + ": vertex " + std::to_string(i) + ": the value of " +
                    property_at(prop.header_line) + " is not a number");
      for (int a = 0; a < 3; ++a)
        if (layout.xyz[a] == static_cast<int>(p)) points[i][a] = v;
      if (layout.intensity == static_cast<int>(p)) intensity[i] = static_cast<float>(v);
    }
  }
  return io_detail::finish_cloud(std::move(points), std::move(intensity), name);
}

// The header pass (declared_points stops here): the plan, its vertex count checked against the data and
// options.max_points; no point decoded.
PlyPlan plan_ply(std::string_view data, const std::string& name, const ReadOptions& options) {
  PlyPlan plan;
  plan.header = parse_header(data, name);
  const PlyHeader& header = plan.header;
  plan.vertex_index = header.elements.size();
  for (std::size_t e = 0; e < header.elements.size(); ++e) {
    if (header.elements[e].name == "vertex") {
      plan.vertex_index = e;
      break;
    }
  }
  if (plan.vertex_index == header.elements.size())
    fail_io(ErrorCode::kInvalidArgument, name, "malformed header: no 'vertex' element");
  plan.layout = find_vertex_layout(plan.vertex(), name);
  if (plan.vertex().count == 0) fail_io(ErrorCode::kInvalidArgument, name, "no points (element vertex 0)");
  if (header.format == PlyFormat::kAscii)
    check_ascii_vertex_count(data, header, plan.vertex(), name);
  else
    plan.binary_vertex_offset = binary_vertex_offset(data, header, plan.vertex_index, name);
  io_detail::check_point_budget(plan.vertex().count, options, name);
  return plan;
}

}  // namespace

PointCloud read_ply_bytes(std::string_view data, const std::string& name, const ReadOptions& options) {
  const PlyPlan plan = plan_ply(data, name, options);
  return plan.header.format == PlyFormat::kAscii ? read_ascii(data, plan, name) : read_binary(data, plan, name);
}

std::uint64_t io_detail::declared_ply_points(std::string_view data, const std::string& name,
                                             const ReadOptions& options) {
  return plan_ply(data, name, options).vertex().count;
}

PointCloud read_ply(const std::string& path, const ReadOptions& options) {
  io_detail::MappedFile file(path);
  return read_ply_bytes(file.bytes(), path, options);
}

void write_ply(const std::string& path, const PointCloud& cloud, PlyEncoding encoding) {
  const bool with_intensity = io_detail::check_cloud_for_writing(cloud, path);
  const bool as_double = !cloud.origin_m.isZero();
  const char* coord_type = as_double ? "double" : "float";
  std::string header = "ply\nformat ";
  header += encoding == PlyEncoding::kAscii                ? "ascii"
            : encoding == PlyEncoding::kBinaryLittleEndian ? "binary_little_endian"
                                                           : "binary_big_endian";
  header += " 1.0\ncomment written by k4reg\nelement vertex " + std::to_string(cloud.size()) + "\n";
  for (const char* axis : {"x", "y", "z"}) header += std::string("property ") + coord_type + " " + axis + "\n";
  if (with_intensity) header += "property float intensity\n";
  header += "end_header\n";

  io_detail::OutputFile out(path);
  out.write(header);
  const std::size_t n = cloud.size();
  if (encoding == PlyEncoding::kAscii) {
    std::string line;
    for (std::size_t i = 0; i < n; ++i) {
      line.clear();
      io_detail::append_ascii_point(line, cloud, i, as_double, with_intensity);
      out.write(line);
    }
  } else {
    const bool swap = (encoding == PlyEncoding::kBinaryBigEndian) != (std::endian::native == std::endian::big);
    const std::size_t record = (as_double ? 24 : 12) + (with_intensity ? 4 : 0);
    constexpr std::size_t kChunk = 1 << 14;
    std::vector<char> buffer(kChunk * record);
    for (std::size_t begin = 0; begin < n; begin += kChunk) {
      const std::size_t end = std::min(n, begin + kChunk);
      char* o = buffer.data();
      for (std::size_t i = begin; i < end; ++i) {
        if (as_double) {
          const Eigen::Vector3d p = io_detail::world_point(cloud, i);
          for (int a = 0; a < 3; ++a) {
            const double v = swap ? io_detail::byteswap_value(p[a]) : p[a];
            std::memcpy(o, &v, 8);
            o += 8;
          }
        } else {
          for (int a = 0; a < 3; ++a) {
            const float v = swap ? io_detail::byteswap_value(cloud.points[i][a]) : cloud.points[i][a];
            std::memcpy(o, &v, 4);
            o += 4;
          }
        }
        if (with_intensity) {
          const float v = swap ? io_detail::byteswap_value(cloud.intensity[i]) : cloud.intensity[i];
          std::memcpy(o, &v, 4);
          o += 4;
        }
      }
      out.write(buffer.data(), static_cast<std::size_t>(o - buffer.data()));
    }
  }
  out.commit();
}

}  // namespace k4reg
