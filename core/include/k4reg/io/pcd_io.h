// PCD (Point Cloud Library) v0.7 reader and writer. See cloud_io.h for the common contract.
//
// Reading: header VERSION, FIELDS, SIZE, TYPE, COUNT, WIDTH, HEIGHT, VIEWPOINT, POINTS, DATA (comment lines
// starting with '#'); DATA ascii, binary and binary_compressed (LZF, fields stored column-wise).
// Fields x y z are required (COUNT 1); intensity is read if present (first of intensity, Intensity,
// scalar_Intensity, reflectance, i); every other field (rgb, normal_x, curvature, COUNT > 1 descriptors,
// "_" padding …) is skipped. VIEWPOINT is ignored (points are returned in the file's frame).
//
// NaN points are SKIPPED, unlike PLY/XYZ: PCL writes invalid returns of organised clouds (HEIGHT > 1) as
// NaN, so a point with any NaN coordinate is dropped silently. ±Inf coordinates are still an error.
// A file whose points are all NaN is an error ("no points").
#pragma once

#include <string>
#include <string_view>

#include "k4reg/io/cloud_io.h"
#include "k4reg/geometry/point_cloud.h"

namespace k4reg {

enum class PcdEncoding { kAscii, kBinary, kBinaryCompressed };

PointCloud read_pcd(const std::string& path, const ReadOptions& options = {});
PointCloud read_pcd_bytes(std::string_view data, const std::string& name, const ReadOptions& options = {});

// Writes FIELDS x y z [intensity] (F4 when origin_m is zero, F8 otherwise; intensity F4), HEIGHT 1.
void write_pcd(const std::string& path, const PointCloud& cloud, PcdEncoding encoding = PcdEncoding::kBinary);

// LZF (liblzf format, as used by PCL's binary_compressed). Exposed for tests.
std::string lzf_compress(std::string_view input);
// Throws kInvalidArgument (message prefixed with `name`) on corrupt input or a size mismatch.
std::string lzf_decompress(std::string_view input, std::size_t expected_size, const std::string& name);

}  // namespace k4reg
