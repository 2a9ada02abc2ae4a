// Each binary format's header pass, for declared_points (declared_points.h): the reader's own first stage, which
// parses the header, checks the declared count against the file's size and ReadOptions::max_points, and returns it
// before a point is decoded. Private to the readers.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "k4reg/io/cloud_io.h"

namespace k4reg::io_detail {

std::uint64_t declared_ply_points(std::string_view data, const std::string& name, const ReadOptions& options);
std::uint64_t declared_pcd_points(std::string_view data, const std::string& name, const ReadOptions& options);
std::uint64_t declared_las_points(std::string_view data, const std::string& name, const ReadOptions& options);
// The records of the selected scans (records with an invalid state included).
std::uint64_t declared_e57_points(std::string_view data, const std::string& name, const ReadOptions& options);

}  // namespace k4reg::io_detail
