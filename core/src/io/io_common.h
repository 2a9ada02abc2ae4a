// Private helpers shared by the point-cloud readers/writers (not installed, not part of the API).
#pragma once

#include <Eigen/Core>
#include <bit>
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "k4reg/io/cloud_io.h"
#include "k4reg/util/error.h"
#include "k4reg/geometry/point_cloud.h"

namespace k4reg::io_detail {

// Limits far above any real file, so that a hostile header or line cannot make a reader allocate more than a
// small multiple of the file's size: tokens on one line (text columns, PCD header values) and header entries
// (PLY elements, PLY properties per element).
constexpr std::size_t kMaxTokensPerLine = 1024;
constexpr std::size_t kMaxHeaderEntries = 1024;

// Throws k4reg::Error(code, "<name>: <message>").
[[noreturn]] void fail_io(ErrorCode code, const std::string& name, const std::string& message);

// A read-only view of a whole file: memory-mapped (no copy). Missing file → kNotFound, a directory or an
// unreadable file → kInvalidArgument / kPermissionDenied.
class MappedFile {
 public:
  explicit MappedFile(const std::string& path);
  ~MappedFile();
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  std::string_view bytes() const { return {static_cast<const char*>(data_), size_}; }

 private:
  void* data_ = nullptr;
  std::size_t size_ = 0;
};

// Refuses `count` points over options.max_points (kResourceExhausted). Readers call it once they know their count
// and before they allocate for the points.
void check_point_budget(std::uint64_t count, const ReadOptions& options, const std::string& name);
// Refuses a scan selection (options.scan_index / scan_name) for a format that holds one scan.
void check_scan_selection(CloudFormat format, const std::string& name, const ReadOptions& options);

// Builds the cloud from world coordinates: refuses an empty list ("no points"), checks every coordinate is
// finite (naming the point) and shifts to a local origin via make_local_cloud.
PointCloud finish_cloud(std::vector<Eigen::Vector3d>&& points, std::vector<float>&& intensity,
                        const std::string& name);

// Lower-case extension including the dot (".ply"), or "" if none.
std::string lower_extension(const std::string& path);

// Text-number parsing: the whole token must be a number ("+1.5", "1e3", "nan", "inf" accepted).
bool parse_double(std::string_view token, double& value);
bool parse_uint64(std::string_view token, std::uint64_t& value);

// "a * b <= limit" without overflow.
inline bool mul_fits(std::uint64_t a, std::uint64_t b, std::uint64_t limit) {
  return b == 0 || a <= limit / b;
}

// World coordinate of point i, in double.
inline Eigen::Vector3d world_point(const PointCloud& cloud, std::size_t i) {
  return cloud.origin_m + cloud.points[i].cast<double>();
}

// Scan formats with an intensity field (LAS, PTX, E57) often fill it with one value when the scanner recorded
// none (LAS: 0, PTX: 0.5); a constant carries no signal for keypoints, so it is dropped.
inline void drop_constant_intensity(std::vector<float>& intensity) {
  for (float value : intensity)
    if (value != intensity.front()) return;
  intensity.clear();
}

// Validates a cloud before writing (intensity size) and returns whether intensity is written.
bool check_cloud_for_writing(const PointCloud& cloud, const std::string& name);

// Buffered output to `<path>.tmp-<pid>`, renamed onto `path` by commit(); the temporary is removed if the
// writer is destroyed without commit(). Write errors map errno to a typed error naming the file.
class OutputFile {
 public:
  explicit OutputFile(const std::string& path);
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  void write(const void* data, std::size_t size);
  void write(std::string_view text) { write(text.data(), text.size()); }
  // Writes and clears `text` once it holds more than 64 KiB: text writers append lines to it and call this.
  void write_batched(std::string& text) {
    if (text.size() <= (1u << 16)) return;
    write(text);
    text.clear();
  }
  void commit();

 private:
  void flush_buffer();
  std::string path_, tmp_path_;
  std::FILE* file_ = nullptr;
  std::vector<char> buffer_;
  std::size_t used_ = 0;
};

// Appends the shortest text that reads back to exactly `value`.
template <typename T>
inline void append_number(std::string& out, T value) {
  char buf[64];
  auto result = std::to_chars(buf, buf + sizeof buf, value);
  out.append(buf, result.ptr);
}

// Appends `value` with a fixed number of decimals.
// One ASCII point line "x y z[ intensity]\n" (PLY and PCD bodies): world coordinates in double when the
// cloud has an origin, the float offsets otherwise.
inline void append_ascii_point(std::string& line, const PointCloud& cloud, std::size_t i, bool as_double,
                               bool with_intensity) {
  const Eigen::Vector3d world = world_point(cloud, i);
  for (int a = 0; a < 3; ++a) {
    if (a) line += ' ';
    if (as_double)
      append_number(line, world[a]);
    else
      append_number(line, cloud.points[i][a]);
  }
  if (with_intensity) {
    line += ' ';
    append_number(line, cloud.intensity[i]);
  }
  line += '\n';
}

inline void append_fixed(std::string& out, double value, int decimals) {
  char buf[128];
  auto result = std::to_chars(buf, buf + sizeof buf, value, std::chars_format::fixed, decimals);
  if (result.ec != std::errc()) {  // absurdly large: fall back to the shortest form
    result = std::to_chars(buf, buf + sizeof buf, value);
  }
  out.append(buf, result.ptr);
}

// Byte swapping for endianness conversion.
template <typename T>
inline T byteswap_value(T value) {
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(bytes[i], bytes[sizeof(T) - 1 - i]);
  std::memcpy(&value, bytes, sizeof(T));
  return value;
}

// Little-endian fields of binary formats (LAS, E57), whatever the host's byte order.
template <typename T>
inline T load_le(const char* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) value = byteswap_value(value);
  return value;
}

template <typename T>
inline void store_le(char* p, T value) {
  if constexpr (std::endian::native == std::endian::big) value = byteswap_value(value);
  std::memcpy(p, &value, sizeof(T));
}

template <typename T>
inline void append_le(std::string& out, T value) {
  char bytes[sizeof(T)];
  store_le(bytes, value);
  out.append(bytes, sizeof(T));
}

// Splits text into lines; `\r\n` and `\n` endings; the last line may lack a newline.
class LineReader {
 public:
  explicit LineReader(std::string_view text) : text_(text) {}
  // Returns false at the end of the text. `line` excludes the line ending.
  bool next(std::string_view& line) {
    if (pos_ >= text_.size()) return false;
    std::size_t end = text_.find('\n', pos_);
    if (end == std::string_view::npos) end = text_.size();
    line = text_.substr(pos_, end - pos_);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos_ = end + 1;
    ++line_number_;
    return true;
  }
  std::size_t line_number() const { return line_number_; }  // 1-based number of the last line returned
  std::size_t position() const { return pos_ > text_.size() ? text_.size() : pos_; }  // start of next line

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  std::size_t line_number_ = 0;
};

// Whitespace tokenizer over a text buffer that tracks line numbers (for ASCII bodies whose records are
// defined by token counts, e.g. PLY ASCII).
class TokenReader {
 public:
  TokenReader(std::string_view text, std::size_t first_line) : text_(text), line_(first_line) {}
  // Returns false at the end of the text.
  bool next(std::string_view& token) {
    while (pos_ < text_.size()) {
      char c = text_[pos_];
      if (c == '\n') {
        ++line_;
      } else if (!(c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v')) {
        break;
      }
      ++pos_;
    }
    if (pos_ >= text_.size()) return false;
    std::size_t start = pos_;
    while (pos_ < text_.size()) {
      char c = text_[pos_];
      if (c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v') break;
      ++pos_;
    }
    token = text_.substr(start, pos_ - start);
    return true;
  }
  std::size_t line() const { return line_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  std::size_t line_;
};

// Splits a line into whitespace/comma-separated tokens (empty tokens between commas are errors reported by
// the caller as non-numeric), clearing `tokens` first. Stops after kMaxTokensPerLine + 1 tokens: callers refuse
// longer lines (tokens.size() > kMaxTokensPerLine) without holding a token per byte.
void split_fields(std::string_view line, std::vector<std::string_view>& tokens);

}  // namespace k4reg::io_detail
