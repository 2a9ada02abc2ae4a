// LAS 1.0–1.4 (ASPRS LiDAR exchange format) reader and writer, uncompressed only. See cloud_io.h for the common
// contract.
//
// Reading: point data record formats 0–10, records found through "offset to point data" and stepped by the
// header's record length (so extra bytes after the standard fields are skipped); the point count is the
// 64-bit one of LAS 1.4 when set, the legacy 32-bit one otherwise. Before anything is allocated, the header
// size, the offset to the point data and count × record length are checked against the file size. X/Y/Z are
// int32 × scale + offset, computed in double.
//
// Intensity: LAS stores an unsigned 16-bit value "normalised to 16 bits", so it is returned divided by 65535
// (0–1). Files whose scanner used fewer bits (0–255, 0–4095) give proportionally smaller values; keypoint
// detection only uses relative contrast, so that does not matter. A file whose intensity is the same for every
// point (most often all 0: the field is mandatory but unused by photogrammetry and many converters) carries no
// signal, and the cloud is returned without intensity.
//
// LAZ (LASzip-compressed LAS: the compression bits 6/7 of the point format, or a LASzip VLR) is refused with
// kInvalidArgument: "LAZ is not supported; decompress with laszip or pdal first".
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "k4reg/io/cloud_io.h"
#include "k4reg/geometry/point_cloud.h"

namespace k4reg {

PointCloud read_las(const std::string& path, const ReadOptions& options = {});
PointCloud read_las_bytes(std::string_view data, const std::string& name, const ReadOptions& options = {});

struct LasWriteOptions {
  int version_minor = 4;        // LAS 1.2, 1.3 or 1.4
  int point_format = 6;         // 0–10; 4/5 need 1.3 or later, 6–10 need 1.4
  std::size_t extra_bytes = 0;  // zero bytes after each record, described by an Extra Bytes VLR (1.4) (≤ 255)
  double resolution_m = 0.0001; // coordinate scale; grown in powers of ten when the extent does not fit int32
};

// Writes world coordinates (origin_m + point) with offset = origin_m, so survey coordinates keep the full
// resolution. Intensity (if any) is mapped linearly from [0, max(1, largest value)] to 0–65535, negative values
// to 0: a cloud read from LAS (0–1) round-trips to within 1/65535. Fields other than X/Y/Z/intensity and the
// return numbers (1 of 1) are zero.
void write_las(const std::string& path, const PointCloud& cloud, const LasWriteOptions& options = {});

}  // namespace k4reg
