// How many points a cloud file can yield, from its header alone, so that a service reserves memory for a file
// before decoding it: a few bytes of compressed PCD or bit-packed E57 can declare gigabytes of points.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "k4reg/io/cloud_io.h"

namespace k4reg {

// The most points read_cloud_bytes(data, name, options) can return, nothing decoded or allocated for them: the
// count a PLY, PCD or LAS header declares, the records of the selected E57 scans, the number of lines of a text
// format (XYZ, PTX; at most options.max_points, which their readers never pass). Throws as read_cloud_bytes does for
// a header it cannot read, and kResourceExhausted for a declared count over options.max_points.
std::uint64_t declared_points(std::string_view data, const std::string& name, const ReadOptions& options = {});

}  // namespace k4reg
