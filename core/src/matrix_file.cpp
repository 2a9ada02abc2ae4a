#include "k4reg/matrix_file.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "k4reg/error.h"

namespace k4reg {

Eigen::Matrix4d read_matrix4(const std::string& path) {
  std::ifstream in(path);
  if (!in) fail(ErrorCode::kNotFound, path + ": cannot open matrix file");
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      if (!(in >> m(r, c)) || !std::isfinite(m(r, c)))
        fail(ErrorCode::kInvalidArgument, path + ": expected 16 finite numbers (4 rows of 4)");
  return m;
}

std::string format_matrix4(const Eigen::Matrix4d& matrix) {
  std::string out;
  char buffer[64];
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      std::snprintf(buffer, sizeof buffer, c ? " %.12g" : "%.12g", matrix(r, c));
      out += buffer;
    }
    out += '\n';
  }
  return out;
}

void write_matrix4(const std::string& path, const Eigen::Matrix4d& matrix) {
  std::ofstream out(path);
  if (!out) fail(ErrorCode::kInvalidArgument, path + ": cannot write matrix file");
  out << format_matrix4(matrix);
  if (!out) fail(ErrorCode::kInvalidArgument, path + ": write failed");
}

}  // namespace k4reg
