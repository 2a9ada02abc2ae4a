// PCD v0.7 reader/writer, including PCL's binary_compressed (LZF, fields stored column-wise).
#include "k4reg/io/pcd_io.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "declared_counts.h"
#include "io_common.h"
#include "k4reg/util/error.h"

namespace k4reg {

using io_detail::fail_io;

// ---------------------------------------------------------------------------------------------------------
// LZF (the liblzf stream format; no header). Control byte c:
//   c < 32  : literal run of c + 1 bytes follows;
//   c >= 32 : back reference, length L = c >> 5 (7 → add the next byte), copy L + 2 bytes from
//             out - ((c & 0x1f) << 8) - next_byte - 1.
// ---------------------------------------------------------------------------------------------------------

std::string lzf_decompress(std::string_view input, std::size_t expected_size, const std::string& name) {
  std::string out(expected_size, '\0');
  const auto* ip = reinterpret_cast<const unsigned char*>(input.data());
  const auto* const in_end = ip + input.size();
  auto* const out_begin = reinterpret_cast<unsigned char*>(out.data());
  unsigned char* op = out_begin;
  unsigned char* const out_end = out_begin + expected_size;
  auto corrupt = [&](const char* what) {
    fail_io(ErrorCode::kInvalidArgument, name,
            std::string("corrupt binary_compressed data: ") + what + " at compressed byte " +
                std::to_string(ip - reinterpret_cast<const unsigned char*>(input.data())));
  };
  while (ip < in_end) {
    unsigned ctrl = *ip++;
    if (ctrl < 32) {
      const std::size_t len = ctrl + 1;
      if (static_cast<std::size_t>(in_end - ip) < len) corrupt("literal run past the end of the input");
      if (static_cast<std::size_t>(out_end - op) < len) corrupt("output larger than the declared size");
      std::memcpy(op, ip, len);
      op += len;
      ip += len;
    } else {
      std::size_t len = ctrl >> 5;
      if (len == 7) {
        if (ip >= in_end) corrupt("back reference past the end of the input");
        len += *ip++;
      }
      if (ip >= in_end) corrupt("back reference past the end of the input");
      const std::size_t back = ((ctrl & 0x1fu) << 8) + *ip++ + 1;
      len += 2;
      if (back > static_cast<std::size_t>(op - out_begin)) corrupt("back reference before the start of the output");
      if (static_cast<std::size_t>(out_end - op) < len) corrupt("output larger than the declared size");
      const unsigned char* ref = op - back;
      for (std::size_t k = 0; k < len; ++k) op[k] = ref[k];  // may overlap: byte by byte
      op += len;
    }
  }
  if (op != out_end)
    fail_io(ErrorCode::kInvalidArgument, name,
            "corrupt binary_compressed data: decompressed to " + std::to_string(op - out_begin) +
                " bytes, header declares " + std::to_string(expected_size));
  return out;
}

std::string lzf_compress(std::string_view input) {
  constexpr std::size_t kMaxLiteral = 32, kMaxOffset = 1 << 13, kMaxMatch = 264, kHashBits = 14;
  const auto* in = reinterpret_cast<const unsigned char*>(input.data());
  const std::size_t n = input.size();
  std::string out;
  out.reserve(n + n / kMaxLiteral + 16);
  std::vector<std::uint32_t> table(std::size_t{1} << kHashBits, 0);  // position + 1 of the last occurrence
  std::size_t literal_start = 0, literal_len = 0;
  auto flush_literals = [&](std::size_t end) {
    while (literal_len > 0) {
      const std::size_t chunk = std::min(literal_len, kMaxLiteral);
      out.push_back(static_cast<char>(chunk - 1));
      out.append(input.data() + literal_start, chunk);
      literal_start += chunk;
      literal_len -= chunk;
    }
    literal_start = end;
  };
  auto hash3 = [&](std::size_t i) {
    const std::uint32_t v = (std::uint32_t{in[i]} << 16) | (std::uint32_t{in[i + 1]} << 8) | in[i + 2];
    return static_cast<std::size_t>((v * 2654435761u) >> (32 - kHashBits));
  };
  std::size_t i = 0;
  while (i < n) {
    if (i + 3 <= n) {
      const std::size_t h = hash3(i);
      const std::uint32_t candidate = table[h];
      table[h] = static_cast<std::uint32_t>(i + 1);
      if (candidate != 0) {
        const std::size_t ref = candidate - 1;
        const std::size_t off = i - ref - 1;
        if (off < kMaxOffset && std::memcmp(in + ref, in + i, 3) == 0) {
          std::size_t len = 3;
          const std::size_t max_len = std::min(kMaxMatch, n - i);
          while (len < max_len && in[ref + len] == in[i + len]) ++len;
          flush_literals(i);
          const std::size_t l = len - 2;
          if (l < 7) {
            out.push_back(static_cast<char>((l << 5) | (off >> 8)));
          } else {
            out.push_back(static_cast<char>((7u << 5) | (off >> 8)));
            out.push_back(static_cast<char>(l - 7));
          }
          out.push_back(static_cast<char>(off & 0xff));
          // Index a couple of positions inside the match so that runs keep matching.
          for (std::size_t k = i + 1; k < i + len && k + 3 <= n && k < i + 3; ++k)
            table[hash3(k)] = static_cast<std::uint32_t>(k + 1);
          i += len;
          literal_start = i;
          continue;
        }
      }
    }
    if (literal_len == 0) literal_start = i;
    ++literal_len;
    ++i;
  }
  flush_literals(n);
  return out;
}

namespace {

struct PcdField {
  std::string name;
  std::size_t size = 4;
  char type = 'F';
  std::size_t count = 1;
  std::size_t offset = 0;  // in a binary record
};

enum class PcdData { kAscii, kBinary, kBinaryCompressed };

struct PcdHeader {
  std::vector<PcdField> fields;
  std::uint64_t width = 0, height = 0, points = 0;
  bool have_width = false, have_height = false, have_points = false;
  PcdData data = PcdData::kAscii;
  std::size_t record_size = 0;
  std::size_t body_offset = 0;
  std::size_t header_lines = 0;
};

std::vector<std::string_view> split_ws(std::string_view line) {
  std::vector<std::string_view> tokens;
  io_detail::split_fields(line, tokens);
  return tokens;
}

PcdHeader parse_header(std::string_view data, const std::string& name) {
  if (data.empty()) fail_io(ErrorCode::kInvalidArgument, name, "empty file");
  PcdHeader header;
  io_detail::LineReader lines(data);
  std::string_view line;
  std::vector<std::string_view> sizes, types, counts;
  bool have_fields = false, have_data = false, first = true;
  while (lines.next(line)) {
    // Built only for an error: headers may have many lines.
    auto where = [&lines] { return "header line " + std::to_string(lines.line_number()) + ": "; };
    std::size_t p = line.find_first_not_of(" \t\r");
    if (p == std::string_view::npos) continue;
    line.remove_prefix(p);
    if (line.front() == '#') continue;
    std::vector<std::string_view> tok = split_ws(line);
    if (tok.empty()) continue;  // separators only (",", "\v", ...)
    if (tok.size() > io_detail::kMaxTokensPerLine)
      fail_io(ErrorCode::kInvalidArgument, name,
              where() + "more than " + std::to_string(io_detail::kMaxTokensPerLine) + " fields or values on one line");
    const std::string_view key = tok[0];
    auto values = [&]() { return std::vector<std::string_view>(tok.begin() + 1, tok.end()); };
    auto one_uint = [&](std::uint64_t& v) {
      if (tok.size() != 2 || !io_detail::parse_uint64(tok[1], v))
        fail_io(ErrorCode::kInvalidArgument, name,
                where() + std::string(key) + " needs one non-negative integer");
    };
    if (key == "VERSION") {
      // Any version string accepted (0.5 … 0.7 share the layout we read).
    } else if (key == "FIELDS" || key == "COLUMNS") {
      for (std::string_view v : values()) {
        PcdField f;
        f.name = std::string(v);
        header.fields.push_back(f);
      }
      have_fields = true;
    } else if (key == "SIZE") {
      sizes = values();
    } else if (key == "TYPE") {
      types = values();
    } else if (key == "COUNT") {
      counts = values();
    } else if (key == "WIDTH") {
      one_uint(header.width);
      header.have_width = true;
    } else if (key == "HEIGHT") {
      one_uint(header.height);
      header.have_height = true;
    } else if (key == "POINTS") {
      one_uint(header.points);
      header.have_points = true;
    } else if (key == "VIEWPOINT") {
      // Sensor pose; points are returned in the file's frame, so it is not applied.
    } else if (key == "DATA") {
      if (tok.size() != 2) fail_io(ErrorCode::kInvalidArgument, name, where() + "malformed DATA line");
      if (tok[1] == "ascii") {
        header.data = PcdData::kAscii;
      } else if (tok[1] == "binary") {
        header.data = PcdData::kBinary;
      } else if (tok[1] == "binary_compressed") {
        header.data = PcdData::kBinaryCompressed;
      } else {
        fail_io(ErrorCode::kInvalidArgument, name,
                where() + "unknown DATA encoding (ascii, binary or binary_compressed are read)");
      }
      have_data = true;
      break;
    } else if (first) {
      fail_io(ErrorCode::kInvalidArgument, name,
              "not a PCD file: the first header line does not start with a PCD keyword");
    } else {
      fail_io(ErrorCode::kInvalidArgument, name, where() + "unknown header keyword");
    }
    first = false;
  }
  if (!have_data) fail_io(ErrorCode::kInvalidArgument, name, "malformed header: no DATA line");
  if (!have_fields || header.fields.empty())
    fail_io(ErrorCode::kInvalidArgument, name, "malformed header: no FIELDS line");
  const std::size_t nf = header.fields.size();
  if (sizes.size() != nf)
    fail_io(ErrorCode::kInvalidArgument, name,
            "malformed header: " + std::to_string(nf) + " FIELDS but " + std::to_string(sizes.size()) + " SIZE values");
  if (types.size() != nf)
    fail_io(ErrorCode::kInvalidArgument, name,
            "malformed header: " + std::to_string(nf) + " FIELDS but " + std::to_string(types.size()) + " TYPE values");
  if (!counts.empty() && counts.size() != nf)
    fail_io(ErrorCode::kInvalidArgument, name,
            "malformed header: " + std::to_string(nf) + " FIELDS but " + std::to_string(counts.size()) +
                " COUNT values");
  std::size_t offset = 0;
  for (std::size_t f = 0; f < nf; ++f) {
    PcdField& field = header.fields[f];
    // Named by position: the field's name is the file's text.
    const std::string field_at = "malformed header: field " + std::to_string(f + 1) + " of " + std::to_string(nf);
    std::uint64_t size = 0, count = 1;
    if (!io_detail::parse_uint64(sizes[f], size) || !(size == 1 || size == 2 || size == 4 || size == 8))
      fail_io(ErrorCode::kInvalidArgument, name,
              field_at + " has a SIZE other than 1, 2, 4 or 8");
    if (types[f].size() != 1 || std::string_view("FIU").find(types[f][0]) == std::string_view::npos)
      fail_io(ErrorCode::kInvalidArgument, name,
              field_at + " has a TYPE other than F, I or U");
    if (types[f][0] == 'F' && size != 4 && size != 8)
      fail_io(ErrorCode::kInvalidArgument, name,
              field_at + " is a float of SIZE " + std::to_string(size) + " (expected 4 or 8)");
    if (!counts.empty() && (!io_detail::parse_uint64(counts[f], count) || count == 0 || count > (1u << 20)))
      fail_io(ErrorCode::kInvalidArgument, name,
              field_at + " has a COUNT that is not an integer from 1 to 2^20");
    field.size = size;
    field.type = types[f][0];
    field.count = count;
    field.offset = offset;
    offset += size * count;
  }
  header.record_size = offset;
  if (!header.have_points) {
    if (!header.have_width) fail_io(ErrorCode::kInvalidArgument, name, "malformed header: no POINTS or WIDTH line");
    const std::uint64_t h = header.have_height ? header.height : 1;
    if (!io_detail::mul_fits(header.width, h, std::numeric_limits<std::uint64_t>::max()))
      fail_io(ErrorCode::kInvalidArgument, name, "malformed header: WIDTH * HEIGHT overflows");
    header.points = header.width * h;
  } else if (header.have_width) {
    const std::uint64_t h = header.have_height ? header.height : 1;
    if (!io_detail::mul_fits(header.width, h, std::numeric_limits<std::uint64_t>::max()) ||
        header.width * h != header.points)
      fail_io(ErrorCode::kInvalidArgument, name,
              "malformed header: POINTS " + std::to_string(header.points) + " != WIDTH " +
                  std::to_string(header.width) + " * HEIGHT " + std::to_string(h));
  }
  header.body_offset = lines.position();
  header.header_lines = lines.line_number();
  return header;
}

constexpr std::array<const char*, 5> kIntensityNames = {"intensity", "Intensity", "scalar_Intensity", "reflectance",
                                                        "scalar_intensity"};

struct PcdLayout {
  std::array<int, 3> xyz = {-1, -1, -1};
  int intensity = -1;
};

PcdLayout find_layout(const PcdHeader& header, const std::string& name) {
  PcdLayout layout;
  // PDAL writes the coordinates as X Y Z: either case names an axis (the lower case first, if both exist).
  const char* axes[3] = {"x", "y", "z"};
  const char* upper_axes[3] = {"X", "Y", "Z"};
  for (int a = 0; a < 3; ++a) {
    for (const char* axis : {axes[a], upper_axes[a]}) {
      for (std::size_t f = 0; f < header.fields.size() && layout.xyz[a] < 0; ++f)
        if (header.fields[f].name == axis) layout.xyz[a] = static_cast<int>(f);
    }
    if (layout.xyz[a] < 0)
      fail_io(ErrorCode::kInvalidArgument, name, std::string("malformed header: no field '") + axes[a] + "'");
    if (header.fields[layout.xyz[a]].count != 1)
      fail_io(ErrorCode::kInvalidArgument, name, std::string("malformed header: field '") + axes[a] + "' has COUNT " +
                                                     std::to_string(header.fields[layout.xyz[a]].count) + " (expected 1)");
  }
  for (const char* candidate : kIntensityNames) {
    for (std::size_t f = 0; f < header.fields.size() && layout.intensity < 0; ++f)
      if (header.fields[f].name == candidate) layout.intensity = static_cast<int>(f);
    if (layout.intensity >= 0) break;
  }
  return layout;
}

inline double load_value(const char* p, char type, std::size_t size) {
  switch (type) {
    case 'F':
      if (size == 4) {
        float v;
        std::memcpy(&v, p, 4);
        return v;
      } else {
        double v;
        std::memcpy(&v, p, 8);
        return v;
      }
    case 'I':
      switch (size) {
        case 1: {
          std::int8_t v;
          std::memcpy(&v, p, 1);
          return v;
        }
        case 2: {
          std::int16_t v;
          std::memcpy(&v, p, 2);
          return v;
        }
        case 4: {
          std::int32_t v;
          std::memcpy(&v, p, 4);
          return v;
        }
        default: {
          std::int64_t v;
          std::memcpy(&v, p, 8);
          return static_cast<double>(v);
        }
      }
    default:
      switch (size) {
        case 1: {
          std::uint8_t v;
          std::memcpy(&v, p, 1);
          return v;
        }
        case 2: {
          std::uint16_t v;
          std::memcpy(&v, p, 2);
          return v;
        }
        case 4: {
          std::uint32_t v;
          std::memcpy(&v, p, 4);
          return v;
        }
        default: {
          std::uint64_t v;
          std::memcpy(&v, p, 8);
          return static_cast<double>(v);
        }
      }
  }
}

template <typename T, typename Out>
void decode_typed(const char* p, std::size_t stride, std::size_t begin, std::size_t end, Out* out,
                  std::size_t out_stride) {
  p += begin * stride;
  out += begin * out_stride;
  for (std::size_t i = begin; i < end; ++i, p += stride, out += out_stride) {
    T v;
    std::memcpy(&v, p, sizeof(T));
    *out = static_cast<Out>(v);
  }
}

// Decodes value i of a field at start + i * stride for i in [begin, end).
template <typename Out>
void decode_field(const PcdField& f, const char* start, std::size_t stride, std::size_t begin, std::size_t end,
                  Out* out, std::size_t out_stride) {
  if (f.type == 'F' && f.size == 4) return decode_typed<float>(start, stride, begin, end, out, out_stride);
  if (f.type == 'F' && f.size == 8) return decode_typed<double>(start, stride, begin, end, out, out_stride);
  const char* p = start + begin * stride;
  for (std::size_t i = begin; i < end; ++i, p += stride) out[i * out_stride] = static_cast<Out>(load_value(p, f.type, f.size));
}

// Drops points with a NaN coordinate (PCL's invalid points) and refuses ±Inf.
void drop_nan_points(std::vector<Eigen::Vector3d>& points, std::vector<float>& intensity, const std::string& name) {
  const bool with_intensity = !intensity.empty();
  std::size_t kept = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d& p = points[i];
    if (std::isnan(p.x()) || std::isnan(p.y()) || std::isnan(p.z())) continue;
    if (!p.allFinite())
      fail_io(ErrorCode::kInvalidArgument, name, "point " + std::to_string(i) + " has an infinite coordinate");
    points[kept] = p;
    if (with_intensity) intensity[kept] = intensity[i];
    ++kept;
  }
  points.resize(kept);
  if (with_intensity) intensity.resize(kept);
}

PointCloud decode_binary(const char* base, const PcdHeader& header, const PcdLayout& layout, bool column_wise,
                         const std::string& name) {
  const std::size_t n = header.points;
  std::vector<Eigen::Vector3d> points(n);
  std::vector<float> intensity(layout.intensity >= 0 ? n : 0);
  double* xyz_out = points.data()->data();
  // Start and stride of each field: interleaved records, or one column per field (binary_compressed).
  std::vector<const char*> starts(header.fields.size());
  std::vector<std::size_t> strides(header.fields.size());
  std::size_t column = 0;
  for (std::size_t f = 0; f < header.fields.size(); ++f) {
    const PcdField& field = header.fields[f];
    if (column_wise) {
      starts[f] = base + column;
      strides[f] = field.size * field.count;
      column += field.size * field.count * n;
    } else {
      starts[f] = base + field.offset;
      strides[f] = header.record_size;
    }
  }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1 << 16), [&](const tbb::blocked_range<std::size_t>& r) {
    for (int a = 0; a < 3; ++a) {
      const int f = layout.xyz[a];
      decode_field(header.fields[f], starts[f], strides[f], r.begin(), r.end(), xyz_out + a, 3);
    }
    if (layout.intensity >= 0) {
      const int f = layout.intensity;
      decode_field(header.fields[f], starts[f], strides[f], r.begin(), r.end(), intensity.data(), 1);
    }
  });
  drop_nan_points(points, intensity, name);
  return io_detail::finish_cloud(std::move(points), std::move(intensity), name);
}

[[noreturn]] void fail_truncated(const std::string& name, const std::string& what) {
  fail_io(ErrorCode::kInvalidArgument, name, "truncated: " + what);
}

// Refuses a count an ASCII body cannot hold: every value takes at least one character and one separator.
void check_ascii_count(std::string_view data, const PcdHeader& header, const std::string& name) {
  const std::uint64_t n = header.points;
  std::size_t values_per_point = 0;
  for (const PcdField& f : header.fields) values_per_point += f.count;
  const std::size_t remaining = data.size() - header.body_offset + 1;
  if (!io_detail::mul_fits(n, 2 * values_per_point, remaining))
    fail_truncated(name, "header says " + std::to_string(n) + " points of " + std::to_string(values_per_point) +
                             " values, but the " + std::to_string(remaining - 1) + "-byte body can hold at most " +
                             std::to_string(remaining / (2 * values_per_point)));
}

PointCloud read_ascii(std::string_view data, const PcdHeader& header, const PcdLayout& layout,
                      const std::string& name) {
  const std::uint64_t n = header.points;
  std::vector<Eigen::Vector3d> points(n);
  std::vector<float> intensity(layout.intensity >= 0 ? n : 0);
  io_detail::TokenReader tokens(data.substr(header.body_offset), header.header_lines + 1);
  std::string_view token;
  for (std::uint64_t i = 0; i < n; ++i) {
    for (std::size_t f = 0; f < header.fields.size(); ++f) {
      const PcdField& field = header.fields[f];
      for (std::size_t c = 0; c < field.count; ++c) {
        if (!tokens.next(token))
          fail_truncated(name, "header says " + std::to_string(n) + " points, data holds " + std::to_string(i) +
                                   " (file ends at line " + std::to_string(tokens.line()) + ")");
        double v;
        if (!io_detail::parse_double(token, v))
          fail_io(ErrorCode::kInvalidArgument, name,
                  "line " + std::to_string(tokens.line()) + ": point " + std::to_string(i) + ": the value of field " +
                      std::to_string(f + 1) + " is not a number");
        if (c != 0) continue;
        for (int a = 0; a < 3; ++a)
          if (layout.xyz[a] == static_cast<int>(f)) points[i][a] = v;
        if (layout.intensity == static_cast<int>(f)) intensity[i] = static_cast<float>(v);
      }
    }
  }
  drop_nan_points(points, intensity, name);
  return io_detail::finish_cloud(std::move(points), std::move(intensity), name);
}

// binary_compressed: uint32 compressed size, uint32 uncompressed size, LZF stream of the column-wise data. Checks
// the sizes against the header and the file; returns the compressed size.
std::uint64_t check_compressed_sizes(std::string_view data, const PcdHeader& header, const std::string& name) {
  const std::uint64_t n = header.points;
  const std::size_t pos = header.body_offset;
  const std::size_t remaining = data.size() - pos;
  const std::size_t stride = header.record_size;
  if (remaining < 8)
    fail_truncated(name, "binary_compressed data needs an 8-byte size prefix, only " + std::to_string(remaining) +
                             " bytes follow the header");
  const std::uint64_t compressed = io_detail::load_le<std::uint32_t>(data.data() + pos);
  const std::uint64_t uncompressed = io_detail::load_le<std::uint32_t>(data.data() + pos + 4);
  if (compressed > remaining - 8)
    fail_truncated(name, "binary_compressed header says " + std::to_string(compressed) + " compressed bytes, only " +
                             std::to_string(remaining - 8) + " follow");
  if (!io_detail::mul_fits(n, stride, std::numeric_limits<std::uint32_t>::max()) || n * stride != uncompressed)
    fail_io(ErrorCode::kInvalidArgument, name,
            "corrupt binary_compressed data: uncompressed size " + std::to_string(uncompressed) + " != POINTS " +
                std::to_string(n) + " * " + std::to_string(stride) + " bytes per point");
  // LZF expands at most ~88x (a 3-byte back reference yields 264 bytes): refuse impossible sizes before
  // allocating.
  if (uncompressed > compressed * 90 + 512)
    fail_truncated(name, "binary_compressed data of " + std::to_string(compressed) + " bytes cannot hold " +
                             std::to_string(n) + " points (" + std::to_string(uncompressed) + " bytes)");
  return compressed;
}

// What the header tells before a point is decoded; for binary_compressed data, the size of its LZF stream.
struct PcdPlan {
  PcdHeader header;
  PcdLayout layout;
  std::uint64_t compressed = 0;
};

// The header pass (declared_points stops here): the plan, its count checked against the data and
// options.max_points; nothing decompressed or decoded.
PcdPlan plan_pcd(std::string_view data, const std::string& name, const ReadOptions& options) {
  PcdPlan plan;
  plan.header = parse_header(data, name);
  const PcdHeader& header = plan.header;
  plan.layout = find_layout(header, name);
  const std::uint64_t n = header.points;
  if (n == 0) fail_io(ErrorCode::kInvalidArgument, name, "no points (POINTS 0)");
  const std::size_t pos = header.body_offset;
  const std::size_t remaining = data.size() - pos;
  const std::size_t stride = header.record_size;
  if (header.data == PcdData::kAscii) {
    check_ascii_count(data, header, name);
  } else if (header.data == PcdData::kBinary) {
    if (!io_detail::mul_fits(n, stride, remaining))
      fail_truncated(name, "header says " + std::to_string(n) + " points, data holds " + std::to_string(remaining / stride) +
                               " (" + std::to_string(stride) + " bytes per point from byte " + std::to_string(pos) +
                               ", file is " + std::to_string(data.size()) + " bytes)");
  } else {
    plan.compressed = check_compressed_sizes(data, header, name);
  }
  io_detail::check_point_budget(n, options, name);
  return plan;
}

}  // namespace

PointCloud read_pcd_bytes(std::string_view data, const std::string& name, const ReadOptions& options) {
  const PcdPlan plan = plan_pcd(data, name, options);
  const PcdHeader& header = plan.header;
  const std::size_t pos = header.body_offset;
  if (header.data == PcdData::kAscii) return read_ascii(data, header, plan.layout, name);
  if (header.data == PcdData::kBinary) return decode_binary(data.data() + pos, header, plan.layout, false, name);
  const std::string raw =
      lzf_decompress(data.substr(pos + 8, plan.compressed), header.points * header.record_size, name);
  return decode_binary(raw.data(), header, plan.layout, true, name);
}

std::uint64_t io_detail::declared_pcd_points(std::string_view data, const std::string& name,
                                             const ReadOptions& options) {
  return plan_pcd(data, name, options).header.points;
}


PointCloud read_pcd(const std::string& path, const ReadOptions& options) {
  io_detail::MappedFile file(path);
  return read_pcd_bytes(file.bytes(), path, options);
}

void write_pcd(const std::string& path, const PointCloud& cloud, PcdEncoding encoding) {
  const bool with_intensity = io_detail::check_cloud_for_writing(cloud, path);
  const bool as_double = !cloud.origin_m.isZero();
  const std::size_t n = cloud.size();
  const std::size_t cs = as_double ? 8 : 4;
  std::string header = "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n";
  header += with_intensity ? "FIELDS x y z intensity\n" : "FIELDS x y z\n";
  header += as_double ? "SIZE 8 8 8" : "SIZE 4 4 4";
  header += with_intensity ? " 4\nTYPE F F F F\nCOUNT 1 1 1 1\n" : "\nTYPE F F F\nCOUNT 1 1 1\n";
  header += "WIDTH " + std::to_string(n) + "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + std::to_string(n) + "\n";
  header += encoding == PcdEncoding::kAscii    ? "DATA ascii\n"
            : encoding == PcdEncoding::kBinary ? "DATA binary\n"
                                               : "DATA binary_compressed\n";
  auto put_coord = [&](char* o, std::size_t i, int a) {
    if (as_double) {
      const double v = cloud.origin_m[a] + static_cast<double>(cloud.points[i][a]);
      std::memcpy(o, &v, 8);
    } else {
      std::memcpy(o, &cloud.points[i][a], 4);
    }
  };

  io_detail::OutputFile out(path);
  out.write(header);
  if (encoding == PcdEncoding::kAscii) {
    std::string line;
    for (std::size_t i = 0; i < n; ++i) {
      line.clear();
      io_detail::append_ascii_point(line, cloud, i, as_double, with_intensity);
      out.write(line);
    }
  } else if (encoding == PcdEncoding::kBinary) {
    const std::size_t record = 3 * cs + (with_intensity ? 4 : 0);
    constexpr std::size_t kChunk = 1 << 14;
    std::vector<char> buffer(kChunk * record);
    for (std::size_t begin = 0; begin < n; begin += kChunk) {
      const std::size_t end = std::min(n, begin + kChunk);
      char* o = buffer.data();
      for (std::size_t i = begin; i < end; ++i) {
        for (int a = 0; a < 3; ++a, o += cs) put_coord(o, i, a);
        if (with_intensity) {
          std::memcpy(o, &cloud.intensity[i], 4);
          o += 4;
        }
      }
      out.write(buffer.data(), static_cast<std::size_t>(o - buffer.data()));
    }
  } else {
    const std::size_t record = 3 * cs + (with_intensity ? 4 : 0);
    if (!io_detail::mul_fits(n, record, std::numeric_limits<std::uint32_t>::max()))
      fail_io(ErrorCode::kInvalidArgument, path, "cannot write binary_compressed: more than 4 GiB of point data");
    std::string columns(n * record, '\0');
    char* o = columns.data();
    for (int a = 0; a < 3; ++a)
      for (std::size_t i = 0; i < n; ++i, o += cs) put_coord(o, i, a);
    if (with_intensity) std::memcpy(o, cloud.intensity.data(), 4 * n);
    const std::string packed = lzf_compress(columns);
    if (packed.size() > std::numeric_limits<std::uint32_t>::max())
      fail_io(ErrorCode::kInvalidArgument, path, "cannot write binary_compressed: compressed data over 4 GiB");
    std::string sizes;
    io_detail::append_le(sizes, static_cast<std::uint32_t>(packed.size()));
    io_detail::append_le(sizes, static_cast<std::uint32_t>(columns.size()));
    out.write(sizes);
    out.write(packed);
  }
  out.commit();
}

}  // namespace k4reg
