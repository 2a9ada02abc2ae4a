#include "k4reg/io/declared_points.h"

#include <algorithm>

#include "declared_counts.h"
#include "io_common.h"

namespace k4reg {

std::uint64_t declared_points(std::string_view data, const std::string& name, const ReadOptions& options) {
  const CloudFormat format = detect_format_bytes(data, name);
  io_detail::check_scan_selection(format, name, options);
  switch (format) {
    case CloudFormat::kPly:
      return io_detail::declared_ply_points(data, name, options);
    case CloudFormat::kPcd:
      return io_detail::declared_pcd_points(data, name, options);
    case CloudFormat::kLas:
      return io_detail::declared_las_points(data, name, options);
    case CloudFormat::kE57:
      return io_detail::declared_e57_points(data, name, options);
    case CloudFormat::kXyz:
    case CloudFormat::kPtx: {
      // Text holds at most one point per line; counting lines is cheap next to parsing them. The text readers
      // refuse a file rather than hold more than options.max_points.
      const std::uint64_t lines = static_cast<std::uint64_t>(std::count(data.begin(), data.end(), '\n')) + 1;
      return options.max_points == 0 ? lines : std::min<std::uint64_t>(lines, options.max_points);
    }
  }
  io_detail::fail_io(ErrorCode::kInternal, name, "unhandled cloud format");
}

}  // namespace k4reg
