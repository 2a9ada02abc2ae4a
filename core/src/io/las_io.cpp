// LAS 1.0–1.4 reader and writer (uncompressed). Rules are documented in las_io.h; field offsets follow the
// ASPRS LAS 1.4 R15 specification, tables 3 (public header block), 4 (VLR header) and 7–17 (point records).
#include "k4reg/io/las_io.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "declared_counts.h"
#include "io_common.h"
#include "k4reg/util/error.h"

namespace k4reg {
namespace {

using io_detail::fail_io;
using io_detail::load_le;

// Public header block offsets (LAS 1.4 table 3).
constexpr std::size_t kHeaderSizeAt = 94, kPointOffsetAt = 96, kVlrCountAt = 100, kPointFormatAt = 104,
                      kRecordLengthAt = 105, kLegacyCountAt = 107, kScaleAt = 131, kOffsetAt = 155, kCount64At = 247;
constexpr std::size_t kHeaderSize12 = 227, kHeaderSize13 = 235, kHeaderSize14 = 375;
constexpr std::size_t kVlrHeaderSize = 54;
constexpr std::size_t kExtraBytesDescriptorSize = 192;
// Shortest record of point data record formats 0–10 (LAS 1.4 tables 7–17).
constexpr std::array<std::size_t, 11> kMinRecordLength = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
constexpr const char* kLazMessage = "LAZ is not supported; decompress with laszip or pdal first";

std::size_t min_header_size(int version_minor) {
  return version_minor >= 4 ? kHeaderSize14 : version_minor == 3 ? kHeaderSize13 : kHeaderSize12;
}

// A LASzip-compressed file keeps the "LASF" header but sets bit 7 (and 6) of the point format and carries a
// VLR of user "laszip encoded". VLRs are only looked at for that; a malformed VLR list is not an error here.
bool has_laszip_vlr(std::string_view data, std::size_t header_size, std::size_t point_offset, std::uint32_t vlrs) {
  std::size_t pos = header_size;
  for (std::uint32_t v = 0; v < vlrs && pos + kVlrHeaderSize <= point_offset; ++v) {
    const std::string_view user = data.substr(pos + 2, 16);
    if (user.substr(0, user.find('\0')) == "laszip encoded") return true;
    pos += kVlrHeaderSize + load_le<std::uint16_t>(data.data() + pos + 20);
  }
  return false;
}

struct LasHeader {
  int version_minor = 0;
  std::size_t point_offset = 0, record_length = 0;
  int point_format = 0;
  std::uint64_t count = 0;
  Eigen::Vector3d scale, offset;
};

LasHeader parse_header(std::string_view data, const std::string& name) {
  if (data.empty()) fail_io(ErrorCode::kInvalidArgument, name, "empty file");
  if (data.substr(0, 4) != "LASF") fail_io(ErrorCode::kInvalidArgument, name, "not a LAS file (wrong magic: no 'LASF')");
  if (data.size() < kHeaderSize12)
    fail_io(ErrorCode::kInvalidArgument, name,
            "truncated: " + std::to_string(data.size()) + " bytes, a LAS header has at least " +
                std::to_string(kHeaderSize12));
  LasHeader h;
  const int major = static_cast<unsigned char>(data[24]);
  h.version_minor = static_cast<unsigned char>(data[25]);
  if (major != 1 || h.version_minor > 4)
    fail_io(ErrorCode::kInvalidArgument, name,
            "unsupported LAS version " + std::to_string(major) + "." + std::to_string(h.version_minor) +
                " (1.0–1.4 are read)");
  const std::size_t header_size = load_le<std::uint16_t>(data.data() + kHeaderSizeAt);
  const std::size_t required = min_header_size(h.version_minor);
  if (header_size < required)
    fail_io(ErrorCode::kInvalidArgument, name,
            "header size " + std::to_string(header_size) + " is below the " + std::to_string(required) +
                " bytes of a LAS 1." + std::to_string(h.version_minor) + " header");
  if (header_size > data.size())
    fail_io(ErrorCode::kInvalidArgument, name,
            "truncated: header size " + std::to_string(header_size) + " but the file has " +
                std::to_string(data.size()) + " bytes");
  h.point_offset = load_le<std::uint32_t>(data.data() + kPointOffsetAt);
  if (h.point_offset < header_size || h.point_offset > data.size())
    fail_io(ErrorCode::kInvalidArgument, name,
            "offset to point data " + std::to_string(h.point_offset) + " is outside the file (header " +
                std::to_string(header_size) + " bytes, file " + std::to_string(data.size()) + " bytes)");
  const unsigned format_byte = static_cast<unsigned char>(data[kPointFormatAt]);
  if ((format_byte & 0xC0u) != 0 ||
      has_laszip_vlr(data, header_size, h.point_offset, load_le<std::uint32_t>(data.data() + kVlrCountAt)))
    fail_io(ErrorCode::kInvalidArgument, name, kLazMessage);
  h.point_format = static_cast<int>(format_byte);
  if (h.point_format > 10)
    fail_io(ErrorCode::kInvalidArgument, name,
            "unsupported point data record format " + std::to_string(h.point_format) + " (0–10 are read)");
  h.record_length = load_le<std::uint16_t>(data.data() + kRecordLengthAt);
  if (h.record_length < kMinRecordLength[h.point_format])
    fail_io(ErrorCode::kInvalidArgument, name,
            "point record length " + std::to_string(h.record_length) + " is below the " +
                std::to_string(kMinRecordLength[h.point_format]) + " bytes of point format " +
                std::to_string(h.point_format));
  h.count = load_le<std::uint32_t>(data.data() + kLegacyCountAt);
  if (h.version_minor >= 4) {
    const std::uint64_t count64 = load_le<std::uint64_t>(data.data() + kCount64At);
    if (count64 != 0) h.count = count64;
  }
  for (int a = 0; a < 3; ++a) {
    h.scale[a] = load_le<double>(data.data() + kScaleAt + 8 * a);
    h.offset[a] = load_le<double>(data.data() + kOffsetAt + 8 * a);
  }
  if (!h.scale.allFinite() || (h.scale.array() == 0.0).any() || !h.offset.allFinite())
    fail_io(ErrorCode::kInvalidArgument, name, "scale factors must be finite and non-zero, offsets finite");
  return h;
}

// The header pass (declared_points stops here): the header, its count checked against the data and
// options.max_points; no record decoded.
LasHeader plan_las(std::string_view data, const std::string& name, const ReadOptions& options) {
  const LasHeader h = parse_header(data, name);
  if (h.count == 0) fail_io(ErrorCode::kInvalidArgument, name, "no points");
  const std::size_t available = data.size() - h.point_offset;
  if (!io_detail::mul_fits(h.count, h.record_length, available))
    fail_io(ErrorCode::kInvalidArgument, name,
            "truncated: the header declares " + std::to_string(h.count) + " points of " +
                std::to_string(h.record_length) + " bytes, but only " + std::to_string(available) +
                " bytes follow the offset to point data " + std::to_string(h.point_offset));
  io_detail::check_point_budget(h.count, options, name);
  return h;
}

}  // namespace

std::uint64_t io_detail::declared_las_points(std::string_view data, const std::string& name,
                                             const ReadOptions& options) {
  return plan_las(data, name, options).count;
}

PointCloud read_las_bytes(std::string_view data, const std::string& name, const ReadOptions& options) {
  const LasHeader h = plan_las(data, name, options);
  const std::size_t n = h.count;
  std::vector<Eigen::Vector3d> points(n);
  std::vector<float> intensity(n);
  const char* records = data.data() + h.point_offset;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1 << 16), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const char* rec = records + i * h.record_length;
      for (int a = 0; a < 3; ++a) points[i][a] = load_le<std::int32_t>(rec + 4 * a) * h.scale[a] + h.offset[a];
      intensity[i] = static_cast<float>(load_le<std::uint16_t>(rec + 12) / 65535.0);
    }
  });
  io_detail::drop_constant_intensity(intensity);
  return io_detail::finish_cloud(std::move(points), std::move(intensity), name);
}

PointCloud read_las(const std::string& path, const ReadOptions& options) {
  io_detail::MappedFile file(path);
  return read_las_bytes(file.bytes(), path, options);
}

namespace {

void append_padded(std::string& out, std::string_view text, std::size_t size) {
  out.append(text.substr(0, size));
  out.append(size - std::min(size, text.size()), '\0');
}

// The smallest power-of-ten multiple of `resolution_m` for which every offset from the origin fits an int32.
double choose_scale(double resolution_m, const PointCloud& cloud) {
  double extent = 0.0;
  for (const Eigen::Vector3f& p : cloud.points) extent = std::max(extent, static_cast<double>(p.cwiseAbs().maxCoeff()));
  double scale = resolution_m;
  while (extent / scale > 2.0e9) scale *= 10.0;
  return scale;
}

void check_options(const LasWriteOptions& o, const std::string& path) {
  if (o.version_minor < 2 || o.version_minor > 4)
    fail_io(ErrorCode::kInvalidArgument, path, "cannot write LAS 1." + std::to_string(o.version_minor) + " (1.2–1.4)");
  if (o.point_format < 0 || o.point_format > 10)
    fail_io(ErrorCode::kInvalidArgument, path, "cannot write point format " + std::to_string(o.point_format));
  const int needs_minor = o.point_format >= 6 ? 4 : o.point_format >= 4 ? 3 : 2;
  if (o.version_minor < needs_minor)
    fail_io(ErrorCode::kInvalidArgument, path,
            "point format " + std::to_string(o.point_format) + " needs LAS 1." + std::to_string(needs_minor));
  if (o.extra_bytes > 255) fail_io(ErrorCode::kInvalidArgument, path, "at most 255 extra bytes per record");
  if (!(o.resolution_m > 0.0) || !std::isfinite(o.resolution_m))
    fail_io(ErrorCode::kInvalidArgument, path, "the resolution must be positive");
}

}  // namespace

void write_las(const std::string& path, const PointCloud& cloud, const LasWriteOptions& options) {
  check_options(options, path);
  const bool with_intensity = io_detail::check_cloud_for_writing(cloud, path);
  if (cloud.empty()) fail_io(ErrorCode::kInvalidArgument, path, "cannot write a LAS file without points");
  const std::size_t n = cloud.size();
  const std::size_t header_size = min_header_size(options.version_minor);
  const std::size_t record_length = kMinRecordLength[options.point_format] + options.extra_bytes;
  const std::uint32_t vlr_count = options.extra_bytes > 0 ? 1 : 0;
  const std::size_t point_offset = header_size + vlr_count * (kVlrHeaderSize + kExtraBytesDescriptorSize);
  const double scale = choose_scale(options.resolution_m, cloud);
  const bool legacy_format = options.point_format < 6;
  if (n > std::numeric_limits<std::uint32_t>::max() && options.version_minor < 4)
    fail_io(ErrorCode::kInvalidArgument, path, "more than 2^32 - 1 points need LAS 1.4");

  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d w = io_detail::world_point(cloud, i);
    lo = lo.cwiseMin(w);
    hi = hi.cwiseMax(w);
  }
  float max_intensity = 1.0f;
  if (with_intensity)
    for (float v : cloud.intensity) max_intensity = std::max(max_intensity, v);

  std::string head;
  head.reserve(point_offset);
  head += "LASF";
  io_detail::append_le<std::uint16_t>(head, 0);                               // file source id
  io_detail::append_le<std::uint16_t>(head, options.point_format >= 6 ? 16 : 0);  // WKT bit: required for 6–10
  head.append(16, '\0');                                                      // project GUID
  head += '\1';
  head += static_cast<char>(options.version_minor);
  append_padded(head, "k4reg", 32);     // system identifier
  append_padded(head, "k4reg write_las", 32);  // generating software
  io_detail::append_le<std::uint16_t>(head, 0);  // creation day of year
  io_detail::append_le<std::uint16_t>(head, 0);  // creation year
  io_detail::append_le<std::uint16_t>(head, static_cast<std::uint16_t>(header_size));
  io_detail::append_le<std::uint32_t>(head, static_cast<std::uint32_t>(point_offset));
  io_detail::append_le<std::uint32_t>(head, vlr_count);
  head += static_cast<char>(options.point_format);
  io_detail::append_le<std::uint16_t>(head, static_cast<std::uint16_t>(record_length));
  const bool legacy_count_fits = legacy_format && n <= std::numeric_limits<std::uint32_t>::max();
  io_detail::append_le<std::uint32_t>(head, legacy_count_fits ? static_cast<std::uint32_t>(n) : 0);
  for (int r = 0; r < 5; ++r) io_detail::append_le<std::uint32_t>(head, r == 0 && legacy_count_fits ? static_cast<std::uint32_t>(n) : 0);
  for (int a = 0; a < 3; ++a) io_detail::append_le<double>(head, scale);
  for (int a = 0; a < 3; ++a) io_detail::append_le<double>(head, cloud.origin_m[a]);
  for (int a = 0; a < 3; ++a) {
    io_detail::append_le<double>(head, hi[a]);
    io_detail::append_le<double>(head, lo[a]);
  }
  if (options.version_minor >= 3) io_detail::append_le<std::uint64_t>(head, 0);  // start of waveform data
  if (options.version_minor >= 4) {
    io_detail::append_le<std::uint64_t>(head, 0);  // start of first EVLR
    io_detail::append_le<std::uint32_t>(head, 0);  // number of EVLRs
    io_detail::append_le<std::uint64_t>(head, n);
    for (int r = 0; r < 15; ++r) io_detail::append_le<std::uint64_t>(head, r == 0 ? n : 0);
  }
  if (options.extra_bytes > 0) {  // one descriptor of data type 0 ("undocumented extra bytes", options = size)
    io_detail::append_le<std::uint16_t>(head, 0);
    append_padded(head, "LASF_Spec", 16);
    io_detail::append_le<std::uint16_t>(head, 4);
    io_detail::append_le<std::uint16_t>(head, kExtraBytesDescriptorSize);
    append_padded(head, "extra bytes", 32);
    const std::size_t descriptor_start = head.size();
    head.append(2, '\0');
    head += '\0';
    head += static_cast<char>(options.extra_bytes);
    append_padded(head, "padding", 32);
    head.append(kExtraBytesDescriptorSize - (head.size() - descriptor_start), '\0');
  }

  io_detail::OutputFile out(path);
  out.write(head);
  std::vector<char> records;
  constexpr std::size_t kBlock = 1 << 16;
  for (std::size_t first = 0; first < n; first += kBlock) {
    const std::size_t count = std::min(kBlock, n - first);
    records.assign(count * record_length, '\0');
    for (std::size_t k = 0; k < count; ++k) {
      const std::size_t i = first + k;
      char* rec = records.data() + k * record_length;
      for (int a = 0; a < 3; ++a)
        io_detail::store_le(rec + 4 * a, static_cast<std::int32_t>(std::lround(cloud.points[i][a] / scale)));
      if (with_intensity) {
        const double v = std::clamp(static_cast<double>(cloud.intensity[i]) / max_intensity, 0.0, 1.0);
        io_detail::store_le(rec + 12, static_cast<std::uint16_t>(std::lround(v * 65535.0)));
      }
      rec[14] = static_cast<char>(legacy_format ? 0x09 : 0x11);  // return 1 of 1
    }
    out.write(records.data(), records.size());
  }
  out.commit();
}

}  // namespace k4reg
