// 4x4 transforms as text: 4 rows of 4 numbers (the simulator's ground truth and `--out` files).
#pragma once

#include <Eigen/Core>
#include <string>

namespace k4reg {

// Throws kNotFound / kInvalidArgument (naming the file) for a missing or malformed file.
Eigen::Matrix4d read_matrix4(const std::string& path);
void write_matrix4(const std::string& path, const Eigen::Matrix4d& matrix);
std::string format_matrix4(const Eigen::Matrix4d& matrix);

}  // namespace k4reg
