// Plain-text point lists (.xyz, .txt, .csv, .pts). Rules are documented in xyz_io.h.
#include "k4reg/io/xyz_io.h"

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "io_common.h"
#include "k4reg/util/error.h"

namespace k4reg {

using io_detail::fail_io;

PointCloud read_xyz_bytes(std::string_view data, const std::string& name, const ReadOptions& options) {
  if (data.empty()) fail_io(ErrorCode::kInvalidArgument, name, "empty file");
  if (data.substr(0, 3) == "\xEF\xBB\xBF") data.remove_prefix(3);  // UTF-8 BOM
  io_detail::LineReader lines(data);
  std::string_view line;
  std::vector<std::string_view> tokens;
  std::vector<Eigen::Vector3d> points;
  std::vector<float> intensity;
  std::size_t columns = 0, columns_line = 0;  // set by the first data line
  bool seen_content = false;                  // any non-comment line seen (header allowed only before)
  while (lines.next(line)) {
    const std::size_t ln = lines.line_number();
    std::size_t p = line.find_first_not_of(" \t\r\f\v");
    if (p == std::string_view::npos) continue;
    line.remove_prefix(p);
    if (line.front() == '#' || line.substr(0, 2) == "//") continue;
    io_detail::split_fields(line, tokens);
    if (tokens.empty()) continue;  // a line of separators only
    if (tokens.size() > io_detail::kMaxTokensPerLine)
      fail_io(ErrorCode::kInvalidArgument, name,
              "line " + std::to_string(ln) + ": more than " + std::to_string(io_detail::kMaxTokensPerLine) + " columns");
    std::uint64_t count_line, rows;
    if (tokens.size() == 1 && io_detail::parse_uint64(tokens[0], count_line)) {  // PTS point count
      seen_content = true;
      continue;
    }
    if (!seen_content && tokens.size() == 3 && (tokens[1] == "x" || tokens[1] == "X") &&
        io_detail::parse_uint64(tokens[0], count_line) && io_detail::parse_uint64(tokens[2], rows)) {
      seen_content = true;  // a 3DTK scan's sweep size, "360 x 225"
      continue;
    }
    double values[4] = {0, 0, 0, 0};
    std::size_t bad = tokens.size();
    for (std::size_t t = 0; t < tokens.size(); ++t) {
      double v;
      if (!io_detail::parse_double(tokens[t], v)) {
        bad = t;
        break;
      }
      if (t < 4) values[t] = v;
    }
    if (bad != tokens.size()) {
      bool all_words = true;
      for (std::string_view t : tokens) {
        double v;
        if (io_detail::parse_double(t, v)) all_words = false;
      }
      if (!seen_content && all_words) {  // a column-name header line such as "x,y,z,intensity"
        seen_content = true;
        continue;
      }
      fail_io(ErrorCode::kInvalidArgument, name,
              "line " + std::to_string(ln) + ": column " + std::to_string(bad + 1) + " is not a number");
    }
    seen_content = true;
    if (tokens.size() < 3)
      fail_io(ErrorCode::kInvalidArgument, name,
              "line " + std::to_string(ln) + ": expected at least 3 numbers (x y z), found " +
                  std::to_string(tokens.size()));
    if (columns == 0) {
      columns = tokens.size();
      columns_line = ln;
    } else if (tokens.size() != columns) {
      fail_io(ErrorCode::kInvalidArgument, name,
              "line " + std::to_string(ln) + " has " + std::to_string(tokens.size()) + " columns but line " +
                  std::to_string(columns_line) + " has " + std::to_string(columns) + ": inconsistent columns");
    }
    if (!std::isfinite(values[0]) || !std::isfinite(values[1]) || !std::isfinite(values[2]))
      fail_io(ErrorCode::kInvalidArgument, name,
              "line " + std::to_string(ln) + ": point " + std::to_string(points.size()) +
                  " has a NaN/Inf coordinate");
    if (options.max_points != 0 && points.size() >= options.max_points)
      fail_io(ErrorCode::kResourceExhausted, name,
              "more than " + std::to_string(options.max_points) + " points (limit exceeded at line " +
                  std::to_string(ln) + ")");
    points.emplace_back(values[0], values[1], values[2]);
    if (columns >= 4) intensity.push_back(static_cast<float>(values[3]));
  }
  if (points.empty()) fail_io(ErrorCode::kInvalidArgument, name, "no points");
  return io_detail::finish_cloud(std::move(points), std::move(intensity), name);
}

PointCloud read_xyz(const std::string& path, const ReadOptions& options) {
  io_detail::MappedFile file(path);
  return read_xyz_bytes(file.bytes(), path, options);
}

void write_xyz(const std::string& path, const PointCloud& cloud, XyzStyle style) {
  const bool with_intensity = io_detail::check_cloud_for_writing(cloud, path);
  const bool as_double = !cloud.origin_m.isZero();
  const char sep = style == XyzStyle::kComma ? ',' : ' ';
  io_detail::OutputFile out(path);
  if (style == XyzStyle::kPtsCount) out.write(std::to_string(cloud.size()) + "\n");
  if (style == XyzStyle::kComma) out.write(with_intensity ? "x,y,z,intensity\n" : "x,y,z\n");
  std::string text;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (as_double) {
      const Eigen::Vector3d p = io_detail::world_point(cloud, i);
      for (int a = 0; a < 3; ++a) {
        if (a) text += sep;
        io_detail::append_fixed(text, p[a], 6);
      }
    } else {
      for (int a = 0; a < 3; ++a) {
        if (a) text += sep;
        io_detail::append_number(text, cloud.points[i][a]);
      }
    }
    if (with_intensity) {
      text += sep;
      io_detail::append_number(text, cloud.intensity[i]);
    }
    text += '\n';
    out.write_batched(text);
  }
  out.write(text);
  out.commit();
}

}  // namespace k4reg
