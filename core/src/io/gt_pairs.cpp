#include "k4reg/io/gt_pairs.h"

#include <cmath>
#include <string_view>

#include "io_common.h"
#include "k4reg/util/error.h"

namespace k4reg {

std::vector<GtPair> read_gt_pairs(const std::string& path) {
  using io_detail::fail_io;
  io_detail::MappedFile file(path);
  io_detail::LineReader lines(file.bytes());
  std::string_view line;
  std::vector<std::string_view> tokens;
  auto next_content = [&](std::string_view& out) {
    while (lines.next(out)) {
      std::size_t p = out.find_first_not_of(" \t\r");
      if (p == std::string_view::npos || out[p] == '#') continue;
      return true;
    }
    return false;
  };
  auto number = [&](std::string_view token, const char* what) {
    double v;
    if (!io_detail::parse_double(token, v) || !std::isfinite(v))
      fail_io(ErrorCode::kInvalidArgument, path,
              "line " + std::to_string(lines.line_number()) + ": " + what + " is not a finite number");
    return v;
  };
  std::vector<GtPair> pairs;
  while (next_content(line)) {
    io_detail::split_fields(line, tokens);
    if (tokens.size() != 4)
      fail_io(ErrorCode::kInvalidArgument, path,
              "line " + std::to_string(lines.line_number()) +
                  ": expected 'source target overlap inlier_rmse', found " + std::to_string(tokens.size()) +
                  " fields");
    const std::size_t record_line = lines.line_number();
    GtPair pair;
    pair.source = std::string(tokens[0]);
    pair.target = std::string(tokens[1]);
    pair.overlap = number(tokens[2], "overlap");
    pair.inlier_rmse = number(tokens[3], "inlier_rmse");
    for (int r = 0; r < 4; ++r) {
      if (!next_content(line))
        fail_io(ErrorCode::kInvalidArgument, path,
                "truncated: the record of line " + std::to_string(record_line) + " has only " + std::to_string(r) +
                    " of 4 matrix rows");
      io_detail::split_fields(line, tokens);
      if (tokens.size() != 4)
        fail_io(ErrorCode::kInvalidArgument, path,
                "line " + std::to_string(lines.line_number()) + ": expected 4 numbers in a matrix row, found " +
                    std::to_string(tokens.size()));
      for (int c = 0; c < 4; ++c) pair.T_target_source(r, c) = number(tokens[c], "matrix entry");
    }
    pairs.push_back(std::move(pair));
  }
  if (pairs.empty()) fail_io(ErrorCode::kInvalidArgument, path, "no pairs");
  return pairs;
}

}  // namespace k4reg
