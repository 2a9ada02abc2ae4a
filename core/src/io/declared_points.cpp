#include "k4reg/io/declared_points.h"

#include <algorithm>

#include "io_common.h"

namespace k4reg {
namespace io_detail {
namespace {

// Set while declared_points() runs a reader: the reader stops where it would allocate for its points.
thread_local bool counting_only = false;

struct Declared {
  std::uint64_t points;
};

}  // namespace

void declare_points(std::uint64_t most) {
  if (counting_only) throw Declared{most};
}

}  // namespace io_detail

std::uint64_t declared_points(std::string_view data, const std::string& name, const ReadOptions& options) {
  const CloudFormat format = detect_format_bytes(data, name);
  // Text holds at most one point per line; counting lines is cheap next to parsing them. The text readers refuse
  // a file rather than hold more than options.max_points.
  if (format == CloudFormat::kXyz || format == CloudFormat::kPtx) {
    const std::uint64_t lines = static_cast<std::uint64_t>(std::count(data.begin(), data.end(), '\n')) + 1;
    return options.max_points == 0 ? lines : std::min<std::uint64_t>(lines, options.max_points);
  }
  // The binary readers declare their count (io_detail::check_point_budget) before allocating: run one up to there.
  struct Counting {
    Counting() { io_detail::counting_only = true; }
    ~Counting() { io_detail::counting_only = false; }
  } counting;
  try {
    read_cloud_bytes(data, name, options);
  } catch (const io_detail::Declared& declared) {
    return declared.points;
  }
  io_detail::fail_io(ErrorCode::kInternal, name, "the reader declared no point count");
}

}  // namespace k4reg
