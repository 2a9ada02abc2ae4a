#include "k4reg/io/matrix_file.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "k4reg/util/error.h"

namespace k4reg {

std::string format_matrix4(const Eigen::Matrix4d& m) {
  std::string out;
  char row[128];
  for (int r = 0; r < 4; ++r) {
    // 17 significant digits: reading the text back gives the same doubles.
    std::snprintf(row, sizeof row, "%.17g %.17g %.17g %.17g\n", m(r, 0), m(r, 1), m(r, 2), m(r, 3));
    out += row;
  }
  return out;
}

void write_matrix4(const std::string& path, const Eigen::Matrix4d& m) {
  std::ofstream out(path);
  if (!out) fail(ErrorCode::kInvalidArgument, path + ": cannot write matrix file: " + std::strerror(errno));
  out << format_matrix4(m);
  out.close();
  if (!out) fail(ErrorCode::kInvalidArgument, path + ": cannot write matrix file");
}

Eigen::Matrix4d read_matrix4(const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    if (!std::filesystem::exists(path)) fail(ErrorCode::kNotFound, path + ": no such matrix file");
    fail(ErrorCode::kInvalidArgument, path + ": cannot read matrix file");
  }
  auto bad = [&](const std::string& why) {
    fail(ErrorCode::kInvalidArgument, path + ": not a 4x4 rigid transform (4 rows of 4 numbers): " + why);
  };
  Eigen::Matrix4d m;
  int count = 0;
  std::string line, token;
  while (std::getline(in, line)) {
    if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    std::istringstream words(line);
    while (words >> token) {
      char* end = nullptr;
      const double value = std::strtod(token.c_str(), &end);
      if (end != token.c_str() + token.size() || !std::isfinite(value))
        bad("number " + std::to_string(count + 1) + " is not a finite number");
      if (count == 16) bad("more than 16 numbers");
      m(count / 4, count % 4) = value;
      ++count;
    }
  }
  if (count != 16) bad(std::to_string(count) + " numbers");
  if ((m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-9) bad("last row is not 0 0 0 1");
  return m;
}

}  // namespace k4reg
