// 4x4 rigid transforms as text: 4 rows of 4 numbers (the simulator's ground truth and `--out` files).
// Reading accepts blank lines and '#' comments and requires a last row of 0 0 0 1.
#pragma once

#include <Eigen/Core>
#include <string>

namespace k4reg {

// Throws kNotFound / kInvalidArgument (naming the file) for a missing or malformed file.
Eigen::Matrix4d read_matrix4(const std::string& path);
void write_matrix4(const std::string& path, const Eigen::Matrix4d& matrix);
std::string format_matrix4(const Eigen::Matrix4d& matrix);

}  // namespace k4reg
