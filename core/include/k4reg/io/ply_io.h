// PLY (Stanford polygon file format) reader and writer. See cloud_io.h for the common contract.
//
// Reading: format ascii / binary_little_endian / binary_big_endian 1.0; comment and obj_info lines;
// any number of elements — only `vertex` is read, others (including ones with list properties, before or
// after the vertex element) are skipped. Scalar types char/uchar/short/ushort/int/uint/float/double and the
// int8…float64 aliases. x, y, z are required; intensity is taken from the first present of
// intensity, scalar_Intensity, reflectance, scalar_intensity, Intensity, i (raw value as float).
// NaN/Inf coordinates are an error naming the vertex index.
#pragma once

#include <string>
#include <string_view>

#include "k4reg/io/cloud_io.h"
#include "k4reg/geometry/point_cloud.h"

namespace k4reg {

enum class PlyEncoding { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

PointCloud read_ply(const std::string& path, const ReadOptions& options = {});
PointCloud read_ply_bytes(std::string_view data, const std::string& name, const ReadOptions& options = {});

// Writes `element vertex` with x y z (float when origin_m is zero, double otherwise) and, when the cloud
// has intensity, `property float intensity`.
void write_ply(const std::string& path, const PointCloud& cloud,
               PlyEncoding encoding = PlyEncoding::kBinaryLittleEndian);

}  // namespace k4reg
