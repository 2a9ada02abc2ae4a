// Format detection, dispatch and the helpers shared by the readers/writers (io_common.h).
#include "k4reg/io/cloud_io.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "io_common.h"
#include "k4reg/io/e57_io.h"
#include "k4reg/util/error.h"
#include "k4reg/io/las_io.h"
#include "k4reg/io/pcd_io.h"
#include "k4reg/io/ply_io.h"
#include "k4reg/io/ptx_io.h"
#include "k4reg/io/xyz_io.h"

namespace k4reg {
namespace io_detail {

void fail_io(ErrorCode code, const std::string& name, const std::string& message) {
  throw Error(code, name + ": " + message);
}

namespace {

ErrorCode code_for_errno(int err) {
  switch (err) {
    case ENOENT:
    case ENOTDIR:
      return ErrorCode::kNotFound;
    case EACCES:
    case EPERM:
    case EROFS:
      return ErrorCode::kPermissionDenied;
    case ENOSPC:
    case EDQUOT:
    case EFBIG:
    case ENOMEM:
    case EMFILE:
    case ENFILE:
      return ErrorCode::kResourceExhausted;
    case EISDIR:
    case ENAMETOOLONG:
    case ELOOP:
      return ErrorCode::kInvalidArgument;
    default:
      return ErrorCode::kInternal;
  }
}

}  // namespace

MappedFile::MappedFile(const std::string& path) {
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    int err = errno;
    if (err == ENOENT || err == ENOTDIR) fail_io(ErrorCode::kNotFound, path, "no such file");
    fail_io(code_for_errno(err), path, std::string("cannot open: ") + std::strerror(err));
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    int err = errno;
    ::close(fd);
    fail_io(code_for_errno(err), path, std::string("cannot stat: ") + std::strerror(err));
  }
  if (S_ISDIR(st.st_mode)) {
    ::close(fd);
    fail_io(ErrorCode::kInvalidArgument, path, "is a directory, not a point-cloud file");
  }
  if (!S_ISREG(st.st_mode)) {
    ::close(fd);
    fail_io(ErrorCode::kInvalidArgument, path, "not a regular file");
  }
  size_ = static_cast<std::size_t>(st.st_size);
  if (size_ > 0) {
    void* p = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd, 0);
    if (p == MAP_FAILED) {
      int err = errno;
      ::close(fd);
      fail_io(code_for_errno(err), path, std::string("cannot map the file: ") + std::strerror(err));
    }
    ::madvise(p, size_, MADV_SEQUENTIAL);
    data_ = p;
  }
  ::close(fd);
}

MappedFile::~MappedFile() {
  if (data_ != nullptr) ::munmap(data_, size_);
}

void check_point_budget(std::uint64_t count, const ReadOptions& options, const std::string& name) {
  if (options.max_points != 0 && count > options.max_points)
    fail_io(ErrorCode::kResourceExhausted, name,
            std::to_string(count) + " points exceed the limit of " + std::to_string(options.max_points));
}

void check_scan_selection(CloudFormat format, const std::string& name, const ReadOptions& options) {
  if ((options.scan_index || !options.scan_name.empty()) && format != CloudFormat::kE57 && format != CloudFormat::kPtx)
    fail_io(ErrorCode::kInvalidArgument, name,
            std::string("a ") + to_string(format) + " file holds one scan; scan selection applies to E57 and PTX files");
}

PointCloud finish_cloud(std::vector<Eigen::Vector3d>&& points, std::vector<float>&& intensity,
                        const std::string& name) {
  if (points.empty()) fail_io(ErrorCode::kInvalidArgument, name, "no points");
  PointCloud cloud = make_local_cloud(points, std::move(intensity), name.c_str());
  points.clear();
  points.shrink_to_fit();
  return cloud;
}

std::string lower_extension(const std::string& path) {
  std::size_t slash = path.find_last_of('/');
  std::size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

bool parse_double(std::string_view token, double& value) {
  if (!token.empty() && token.front() == '+') {
    token.remove_prefix(1);
    if (!token.empty() && (token.front() == '+' || token.front() == '-')) return false;
  }
  if (token.empty()) return false;
  auto result = std::from_chars(token.data(), token.data() + token.size(), value);
  return result.ec == std::errc() && result.ptr == token.data() + token.size();
}

bool parse_uint64(std::string_view token, std::uint64_t& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty()) return false;
  auto result = std::from_chars(token.data(), token.data() + token.size(), value);
  return result.ec == std::errc() && result.ptr == token.data() + token.size();
}

bool check_cloud_for_writing(const PointCloud& cloud, const std::string& name) {
  if (!cloud.intensity.empty() && cloud.intensity.size() != cloud.points.size())
    fail_io(ErrorCode::kInvalidArgument, name,
            "cannot write: " + std::to_string(cloud.intensity.size()) + " intensity values for " +
                std::to_string(cloud.points.size()) + " points");
  if (!cloud.origin_m.allFinite()) fail_io(ErrorCode::kInvalidArgument, name, "cannot write: origin is NaN/Inf");
  return cloud.has_intensity();
}

void split_fields(std::string_view line, std::vector<std::string_view>& tokens) {
  tokens.clear();
  std::size_t i = 0, n = line.size();
  auto is_sep = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == ',' || c == ';' || c == '\f' || c == '\v'; };
  while (i < n && tokens.size() <= kMaxTokensPerLine) {
    while (i < n && is_sep(line[i])) ++i;
    if (i >= n) break;
    std::size_t start = i;
    while (i < n && !is_sep(line[i])) ++i;
    tokens.push_back(line.substr(start, i - start));
  }
}

// ---- OutputFile ----

OutputFile::OutputFile(const std::string& path) : path_(path) {
  static std::atomic<unsigned> counter{0};
  tmp_path_ = path + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
  file_ = std::fopen(tmp_path_.c_str(), "wb");
  if (file_ == nullptr) {
    int err = errno;
    if (err == ENOENT) fail_io(ErrorCode::kNotFound, path, "cannot write: the directory does not exist");
    fail_io(code_for_errno(err), path, std::string("cannot write: ") + std::strerror(err));
  }
  buffer_.resize(std::size_t{1} << 20);
}

OutputFile::~OutputFile() {
  if (file_ != nullptr) {
    std::fclose(file_);
    std::remove(tmp_path_.c_str());
  }
}

void OutputFile::flush_buffer() {
  if (used_ == 0) return;
  if (std::fwrite(buffer_.data(), 1, used_, file_) != used_) {
    int err = errno;
    fail_io(code_for_errno(err), path_, std::string("write failed: ") + std::strerror(err));
  }
  used_ = 0;
}

void OutputFile::write(const void* data, std::size_t size) {
  if (size > buffer_.size() - used_) {
    flush_buffer();
    if (size >= buffer_.size()) {
      if (std::fwrite(data, 1, size, file_) != size) {
        int err = errno;
        fail_io(code_for_errno(err), path_, std::string("write failed: ") + std::strerror(err));
      }
      return;
    }
  }
  std::memcpy(buffer_.data() + used_, data, size);
  used_ += size;
}

void OutputFile::commit() {
  flush_buffer();
  std::FILE* f = file_;
  file_ = nullptr;
  if (std::fclose(f) != 0) {
    int err = errno;
    std::remove(tmp_path_.c_str());
    fail_io(code_for_errno(err), path_, std::string("write failed: ") + std::strerror(err));
  }
  if (std::rename(tmp_path_.c_str(), path_.c_str()) != 0) {
    int err = errno;
    std::remove(tmp_path_.c_str());
    fail_io(code_for_errno(err), path_, std::string("cannot rename the written file into place: ") + std::strerror(err));
  }
}

}  // namespace io_detail

using io_detail::fail_io;

const char* to_string(CloudFormat format) {
  switch (format) {
    case CloudFormat::kPly:
      return "PLY";
    case CloudFormat::kPcd:
      return "PCD";
    case CloudFormat::kXyz:
      return "XYZ";
    case CloudFormat::kLas:
      return "LAS";
    case CloudFormat::kPtx:
      return "PTX";
    case CloudFormat::kE57:
      return "E57";
  }
  return "unknown";
}

namespace {

bool extension_format(const std::string& path, CloudFormat& format) {
  const std::string ext = io_detail::lower_extension(path);
  if (ext == ".ply") {
    format = CloudFormat::kPly;
  } else if (ext == ".pcd") {
    format = CloudFormat::kPcd;
  } else if (ext == ".xyz" || ext == ".txt" || ext == ".pts" || ext == ".csv" || ext == ".asc" || ext == ".3d") {
    format = CloudFormat::kXyz;
  } else if (ext == ".las" || ext == ".laz") {  // the LAS reader refuses compressed (LAZ) content
    format = CloudFormat::kLas;
  } else if (ext == ".ptx") {
    format = CloudFormat::kPtx;
  } else if (ext == ".e57") {
    format = CloudFormat::kE57;
  } else {
    return false;
  }
  return true;
}

bool starts_with(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

// Does the start of the buffer look like a PCD header? (first non-comment line VERSION/FIELDS, or a
// "# .PCD" comment line first).
bool looks_like_pcd(std::string_view data) {
  io_detail::LineReader lines(data.substr(0, 4096));
  std::string_view line;
  for (int i = 0; i < 32 && lines.next(line); ++i) {
    std::size_t p = line.find_first_not_of(" \t");
    if (p == std::string_view::npos) continue;
    line.remove_prefix(p);
    if (starts_with(line, "# .PCD") || starts_with(line, "#.PCD")) return true;
    if (line.front() == '#') continue;
    return starts_with(line, "VERSION") || starts_with(line, "FIELDS");
  }
  return false;
}

// Does the start of the buffer look like numeric text (a line of numbers within the first lines, after
// comments, an optional header line and an optional count line)?
bool looks_like_numeric_text(std::string_view data) {
  std::string_view head = data.substr(0, 8192);
  for (char c : head)
    if (c == '\0') return false;
  io_detail::LineReader lines(head);
  std::string_view line;
  std::vector<std::string_view> tokens;
  for (int i = 0; i < 8 && lines.next(line); ++i) {
    io_detail::split_fields(line, tokens);
    if (tokens.empty() || tokens[0].front() == '#' || starts_with(tokens[0], "//")) continue;
    bool all_numbers = true;
    for (std::string_view t : tokens) {
      double v;
      if (!io_detail::parse_double(t, v)) all_numbers = false;
    }
    if (all_numbers && tokens.size() >= 3) return true;
  }
  return false;
}

}  // namespace

CloudFormat format_from_extension(const std::string& path) {
  CloudFormat format;
  if (io_detail::lower_extension(path) == ".laz")
    fail_io(ErrorCode::kInvalidArgument, path, "LAZ is not supported; decompress with laszip or pdal first");
  if (!extension_format(path, format))
    fail_io(ErrorCode::kInvalidArgument, path,
            "unknown point-cloud extension '" + io_detail::lower_extension(path) +
                "' (supported: .ply, .pcd, .xyz, .txt, .csv, .pts, .asc, .las, .ptx, .e57)");
  return format;
}

CloudFormat detect_format_bytes(std::string_view data, const std::string& name) {
  std::string_view body = data;
  if (starts_with(body, "\xEF\xBB\xBF")) body.remove_prefix(3);  // UTF-8 BOM
  if (starts_with(body, "ply\n") || starts_with(body, "ply\r\n")) return CloudFormat::kPly;
  if (starts_with(data, "LASF")) return CloudFormat::kLas;
  if (starts_with(data, "ASTM-E57")) return CloudFormat::kE57;
  if (looks_like_pcd(body)) return CloudFormat::kPcd;
  if (looks_like_ptx(body)) return CloudFormat::kPtx;  // before XYZ: a PTX header is numeric text too
  CloudFormat by_extension;
  const bool has_extension = extension_format(name, by_extension);
  // A .ply/.pcd file without its magic goes to its own reader, which names the problem ("wrong magic").
  if (has_extension && by_extension != CloudFormat::kXyz) return by_extension;
  if (looks_like_numeric_text(body)) return CloudFormat::kXyz;
  if (has_extension) return by_extension;
  if (data.empty()) fail_io(ErrorCode::kInvalidArgument, name, "empty file");
  fail_io(ErrorCode::kInvalidArgument, name,
          "cannot determine the point-cloud format: not PLY, LAS, E57, PCD, PTX or numeric text");
}

CloudFormat detect_format(const std::string& path) {
  io_detail::MappedFile file(path);
  return detect_format_bytes(file.bytes(), path);
}

PointCloud read_cloud_bytes(std::string_view data, const std::string& name, const ReadOptions& options) {
  const CloudFormat format = detect_format_bytes(data, name);
  io_detail::check_scan_selection(format, name, options);
  switch (format) {
    case CloudFormat::kPly:
      return read_ply_bytes(data, name, options);
    case CloudFormat::kPcd:
      return read_pcd_bytes(data, name, options);
    case CloudFormat::kXyz:
      return read_xyz_bytes(data, name, options);
    case CloudFormat::kLas:
      return read_las_bytes(data, name, options);
    case CloudFormat::kPtx:
      return read_ptx_bytes(data, name, options);
    case CloudFormat::kE57:
      return read_e57_bytes(data, name, options);
  }
  fail_io(ErrorCode::kInternal, name, "unhandled cloud format");
}

PointCloud read_cloud(const std::string& path, const ReadOptions& options) {
  io_detail::MappedFile file(path);
  return read_cloud_bytes(file.bytes(), path, options);
}

std::size_t count_scans(const std::string& path) {
  switch (detect_format(path)) {
    case CloudFormat::kE57: {
      io_detail::MappedFile file(path);
      return count_e57_scans(file.bytes(), path);
    }
    case CloudFormat::kPtx: {
      io_detail::MappedFile file(path);
      return count_ptx_scans(file.bytes(), path);
    }
    default:
      return 1;
  }
}

void write_cloud(const std::string& path, const PointCloud& cloud) {
  const std::string ext = io_detail::lower_extension(path);
  switch (format_from_extension(path)) {
    case CloudFormat::kPly:
      write_ply(path, cloud, PlyEncoding::kBinaryLittleEndian);
      return;
    case CloudFormat::kPcd:
      write_pcd(path, cloud, PcdEncoding::kBinary);
      return;
    case CloudFormat::kXyz:
      write_xyz(path, cloud, ext == ".csv" ? XyzStyle::kComma : ext == ".pts" ? XyzStyle::kPtsCount : XyzStyle::kSpace);
      return;
    case CloudFormat::kLas:
      write_las(path, cloud);
      return;
    case CloudFormat::kPtx:
      write_ptx(path, {PtxScan{cloud}});
      return;
    case CloudFormat::kE57: {
      E57Scan scan;
      scan.name = "scan";
      scan.cloud = cloud;
      write_e57(path, {scan});
      return;
    }
  }
}

}  // namespace k4reg
