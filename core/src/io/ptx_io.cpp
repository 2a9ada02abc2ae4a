// PTX (Leica Cyclone ASCII) reader and writer. Rules are documented in ptx_io.h.
#include "k4reg/io/ptx_io.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "io_common.h"
#include "k4reg/util/error.h"

namespace k4reg {
namespace {

using io_detail::fail_io;

// Shortest point line: "0 0 0\n".
constexpr std::size_t kMinPointLineBytes = 6;

struct ScanHeader {
  std::uint64_t columns = 0, rows = 0;
  Eigen::Matrix4d scanner_to_file = Eigen::Matrix4d::Identity();  // column-vector convention
};

// Splits the next line into numbers; false if the line does not hold exactly `count` numbers.
bool numbers_line(io_detail::LineReader& lines, std::vector<std::string_view>& tokens, std::size_t count,
                  double* values) {
  std::string_view line;
  if (!lines.next(line)) return false;
  io_detail::split_fields(line, tokens);
  if (tokens.size() != count) return false;
  for (std::size_t i = 0; i < count; ++i)
    if (!io_detail::parse_double(tokens[i], values[i]) || !std::isfinite(values[i])) return false;
  return true;
}

bool count_line(io_detail::LineReader& lines, std::vector<std::string_view>& tokens, std::uint64_t& value) {
  std::string_view line;
  if (!lines.next(line)) return false;
  io_detail::split_fields(line, tokens);
  return tokens.size() == 1 && io_detail::parse_uint64(tokens[0], value);
}

bool blank(std::string_view line) { return line.find_first_not_of(" \t\r\f\v") == std::string_view::npos; }

// Skips blank lines; false at the end of the text.
bool skip_blank_lines(io_detail::LineReader& lines) {
  io_detail::LineReader peek = lines;
  std::string_view line;
  while (peek.next(line)) {
    if (!blank(line)) return true;
    lines = peek;
  }
  return false;
}

// What parse_header found wrong: the line it expected, and whether the text ended before that line.
struct HeaderProblem {
  const char* expected = nullptr;
  bool ended = false;
};

bool at_end(const io_detail::LineReader& lines) {
  io_detail::LineReader peek = lines;
  std::string_view line;
  return !peek.next(line);
}

// Parses one scan header (10 lines); `expected` stays nullptr when it is well-formed.
HeaderProblem parse_header(io_detail::LineReader& lines, ScanHeader& h) {
  static constexpr struct {
    const char* expected;
    std::size_t numbers;  // 0: a count
  } kLines[10] = {{"the column count", 0},
                  {"the row count", 0},
                  {"the scanner position (3 numbers)", 3},
                  {"a scanner axis (3 numbers)", 3},
                  {"a scanner axis (3 numbers)", 3},
                  {"a scanner axis (3 numbers)", 3},
                  {"a row of the 4x4 matrix (4 numbers)", 4},
                  {"a row of the 4x4 matrix (4 numbers)", 4},
                  {"a row of the 4x4 matrix (4 numbers)", 4},
                  {"a row of the 4x4 matrix (4 numbers)", 4}};
  std::vector<std::string_view> tokens;
  Eigen::Matrix4d written;  // as in the file: row vectors, translation in the last row
  for (int l = 0; l < 10; ++l) {
    if (at_end(lines)) return {kLines[l].expected, true};
    double v[4];
    const bool ok = kLines[l].numbers == 0 ? count_line(lines, tokens, l == 0 ? h.columns : h.rows)
                                           : numbers_line(lines, tokens, kLines[l].numbers, v);
    if (!ok) return {kLines[l].expected, false};
    if (l >= 6)
      for (int c = 0; c < 4; ++c) written(l - 6, c) = v[c];
  }
  if (written.col(3).head<3>().cwiseAbs().maxCoeff() > 1e-6 || std::abs(written(3, 3) - 1.0) > 1e-6)
    return {"the 4x4 matrix (its last column must be 0 0 0 1)", false};
  h.scanner_to_file = written.transpose();
  h.scanner_to_file.row(3) << 0, 0, 0, 1;
  return {};
}

// Whether the values from `first` on are not all the same (a constant intensity is no intensity).
bool varies(const std::vector<float>& values, std::size_t first) {
  for (std::size_t i = first; i < values.size(); ++i)
    if (values[i] != values[first]) return true;
  return false;
}

}  // namespace

bool looks_like_ptx(std::string_view data) {
  io_detail::LineReader lines(data.substr(0, 4096));
  ScanHeader h;
  return skip_blank_lines(lines) && parse_header(lines, h).expected == nullptr;
}

PointCloud read_ptx_bytes(std::string_view data, const std::string& name, const ReadOptions& options) {
  if (data.empty()) fail_io(ErrorCode::kInvalidArgument, name, "empty file");
  if (!options.scan_name.empty())
    fail_io(ErrorCode::kInvalidArgument, name,
            "PTX scans have no names; select scan '" + options.scan_name + "' by its index instead");
  io_detail::LineReader lines(data);
  std::vector<Eigen::Vector3d> points;
  std::vector<float> intensity;
  std::vector<std::string_view> tokens;
  std::size_t scans = 0, selected_scans = 0, scans_with_intensity = 0;
  Eigen::Vector3d scanner_m = Eigen::Vector3d::Zero();  // the last selected scan's
  for (; skip_blank_lines(lines); ++scans) {
    ScanHeader h;
    const HeaderProblem problem = parse_header(lines, h);
    if (problem.ended)
      fail_io(ErrorCode::kInvalidArgument, name,
              "truncated: the file ends in scan " + std::to_string(scans) + "'s header, which lacks " + problem.expected);
    if (problem.expected)
      fail_io(ErrorCode::kInvalidArgument, name,
              "line " + std::to_string(lines.line_number()) + ": scan " + std::to_string(scans) + " header: expected " +
                  problem.expected);
    const std::size_t remaining = data.size() - lines.position();
    if (!io_detail::mul_fits(h.columns, h.rows, (remaining + 1) / kMinPointLineBytes))
      fail_io(ErrorCode::kInvalidArgument, name,
              "truncated: scan " + std::to_string(scans) + " declares " + std::to_string(h.columns) + " x " +
                  std::to_string(h.rows) + " points, but only " + std::to_string(remaining) + " bytes follow");
    const std::uint64_t cells = h.columns * h.rows;
    const bool selected = !options.scan_index || *options.scan_index == scans;
    std::size_t columns = 0;  // of this scan's point lines, set by its first line
    std::string_view line;
    if (selected) {
      ++selected_scans;
      if (points.capacity() < points.size() + cells) points.reserve(std::max(2 * points.capacity(), points.size() + cells));
    }
    const std::size_t first_point = points.size(), first_intensity = intensity.size();
    const Eigen::Matrix4d to_file = options.apply_pose ? h.scanner_to_file : Eigen::Matrix4d::Identity();
    const Eigen::Matrix3d rotation = to_file.topLeftCorner<3, 3>();
    const Eigen::Vector3d translation = to_file.topRightCorner<3, 1>();
    if (selected) scanner_m = translation;
    for (std::uint64_t cell = 0; cell < cells; ++cell) {
      if (!lines.next(line))
        fail_io(ErrorCode::kInvalidArgument, name,
                "truncated: scan " + std::to_string(scans) + " declares " + std::to_string(cells) +
                    " points, the file ends after " + std::to_string(cell));
      if (!selected) continue;
      const std::size_t ln = lines.line_number();
      io_detail::split_fields(line, tokens);
      double v[4] = {0, 0, 0, 0};
      for (std::size_t t = 0; t < tokens.size(); ++t) {
        double value;
        if (!io_detail::parse_double(tokens[t], value))
          fail_io(ErrorCode::kInvalidArgument, name,
                  "line " + std::to_string(ln) + ": column " + std::to_string(t + 1) + " is not a number");
        if (t < 4) v[t] = value;
      }
      const bool no_return = tokens.size() >= 3 && v[0] == 0.0 && v[1] == 0.0 && v[2] == 0.0;
      if (columns == 0 && !no_return) {
        columns = tokens.size();
        if (columns != 3 && columns != 4 && columns != 7)
          fail_io(ErrorCode::kInvalidArgument, name,
                  "line " + std::to_string(ln) + ": expected x y z [intensity [r g b]] (3, 4 or 7 numbers), found " +
                      std::to_string(columns));
      }
      if (no_return) continue;
      if (tokens.size() != columns)
        fail_io(ErrorCode::kInvalidArgument, name,
                "line " + std::to_string(ln) + " has " + std::to_string(tokens.size()) + " columns, the scan's " +
                    "first point has " + std::to_string(columns) + ": inconsistent columns");
      if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
        fail_io(ErrorCode::kInvalidArgument, name, "line " + std::to_string(ln) + ": NaN/Inf coordinate");
      if (options.max_points != 0 && points.size() >= options.max_points)
        fail_io(ErrorCode::kResourceExhausted, name,
                "more than " + std::to_string(options.max_points) + " points (limit exceeded at line " +
                    std::to_string(ln) + ")");
      points.push_back(rotation * Eigen::Vector3d(v[0], v[1], v[2]) + translation);
      if (columns >= 4) intensity.push_back(static_cast<float>(v[3]));
    }
    // A selected scan without valid points has no say; one without (varying) intensity drops it for all.
    if (selected && (points.size() == first_point || (columns >= 4 && varies(intensity, first_intensity))))
      ++scans_with_intensity;
  }
  if (scans == 0) fail_io(ErrorCode::kInvalidArgument, name, "no scans (only blank lines)");
  if (options.scan_index && *options.scan_index >= scans)
    fail_io(ErrorCode::kInvalidArgument, name,
            "scan index " + std::to_string(*options.scan_index) + " does not exist: the file has " +
                std::to_string(scans) + " scan" + (scans == 1 ? "" : "s") + " (0-based)");
  if (scans_with_intensity != selected_scans) intensity.clear();
  PointCloud cloud = io_detail::finish_cloud(std::move(points), std::move(intensity), name);
  if (selected_scans == 1) cloud.scanner_m = scanner_m;  // merged scans have no one scanner
  return cloud;
}

std::size_t count_ptx_scans(std::string_view data, const std::string& name) {
  io_detail::LineReader lines(data);
  std::string_view line;
  std::size_t scans = 0;
  for (; skip_blank_lines(lines); ++scans) {
    ScanHeader h;
    if (const HeaderProblem problem = parse_header(lines, h); problem.expected)
      fail_io(ErrorCode::kInvalidArgument, name, "scan " + std::to_string(scans) + " header: expected " + problem.expected);
    if (!io_detail::mul_fits(h.columns, h.rows, data.size()))
      fail_io(ErrorCode::kInvalidArgument, name, "truncated: scan " + std::to_string(scans) + " declares more points than bytes");
    for (std::uint64_t cell = 0; cell < h.columns * h.rows; ++cell)
      if (!lines.next(line)) fail_io(ErrorCode::kInvalidArgument, name, "truncated: scan " + std::to_string(scans));
  }
  if (scans == 0) fail_io(ErrorCode::kInvalidArgument, name, "no scans (only blank lines)");
  return scans;
}

PointCloud read_ptx(const std::string& path, const ReadOptions& options) {
  io_detail::MappedFile file(path);
  return read_ptx_bytes(file.bytes(), path, options);
}

void write_ptx(const std::string& path, const std::vector<PtxScan>& scans) {
  if (scans.empty()) fail_io(ErrorCode::kInvalidArgument, path, "cannot write a PTX file without scans");
  io_detail::OutputFile out(path);
  std::string text;
  for (std::size_t s = 0; s < scans.size(); ++s) {
    const PtxScan& scan = scans[s];
    const bool with_intensity = io_detail::check_cloud_for_writing(scan.cloud, path);
    const std::size_t n = scan.cloud.size();
    const std::size_t columns = scan.columns == 0 ? n : scan.columns;
    if (n == 0 || n % columns != 0)
      fail_io(ErrorCode::kInvalidArgument, path,
              "cannot write scan " + std::to_string(s) + ": " + std::to_string(n) + " points do not fill a grid of " +
                  std::to_string(columns) + " columns");
    const Eigen::Matrix4d& m = scan.scanner_to_file;
    if (!m.allFinite() || m.row(3) != Eigen::RowVector4d(0, 0, 0, 1))
      fail_io(ErrorCode::kInvalidArgument, path,
              "cannot write scan " + std::to_string(s) + ": the pose must be finite with a last row 0 0 0 1");
    text += std::to_string(columns) + "\n" + std::to_string(n / columns) + "\n";
    auto numbers = [&](std::initializer_list<double> values) {
      bool first = true;
      for (double v : values) {
        if (!first) text += ' ';
        first = false;
        io_detail::append_number(text, v);
      }
      text += '\n';
    };
    numbers({m(0, 3), m(1, 3), m(2, 3)});
    for (int axis = 0; axis < 3; ++axis) numbers({m(0, axis), m(1, axis), m(2, axis)});
    for (int axis = 0; axis < 3; ++axis) numbers({m(0, axis), m(1, axis), m(2, axis), 0.0});
    numbers({m(0, 3), m(1, 3), m(2, 3), 1.0});
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d p = io_detail::world_point(scan.cloud, i);
      for (int a = 0; a < 3; ++a) {
        io_detail::append_fixed(text, p[a], 6);
        text += ' ';
      }
      if (with_intensity)
        io_detail::append_number(text, scan.cloud.intensity[i]);
      else
        text += '0';
      text += '\n';
      out.write_batched(text);
    }
  }
  out.write(text);
  out.commit();
}

}  // namespace k4reg
