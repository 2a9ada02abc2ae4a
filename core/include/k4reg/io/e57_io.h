// E57 (ASTM E2807, the exchange format of terrestrial laser scanners) reader and writer. See cloud_io.h for the
// common contract.
//
// Reading:
// - The paged file: every 1024-byte page ends in the CRC-32C of its 1020 data bytes. Each page the reader uses
//   (the header, the XML, the binary sections of the selected scans) is checked; a mismatch is kDataLoss
//   ("CRC-32C mismatch in page N"). A file shorter than its header's declared length is "truncated"
//   (kInvalidArgument).
// - The XML section (pugixml): /data3D holds the scans. Each scan's `points` CompressedVector is decoded with the
//   bitPackCodec (the only codec of the standard): cartesianX/Y/Z, or sphericalRange/Azimuth/Elevation when the
//   prototype has no Cartesian fields, each as Float (single or double), Integer or ScaledInteger
//   (integer × scale + offset, bit-packed in the fewest bits that hold maximum − minimum). Records whose
//   cartesianInvalidState / sphericalInvalidState is not 0 (1 = direction only, 2 = no return) are skipped.
// - intensity is normalised to 0–1 by the scan's intensityLimits (or, without them, by the field's declared
//   Integer/ScaledInteger range; a Float field without limits is taken as is). Constant intensity is dropped; so
//   is intensity when not every selected scan has it.
// - Each scan's pose (rotation quaternion w x y z + translation) is applied: points come out in the file's
//   common frame, which for a registered project is the project (often a national grid) frame.
// - recordCount, section offsets and lengths are checked against the file before anything is allocated.
//
// Scans: by default all scans are merged in the common frame (what a registered project export means, and what
// PDAL and CloudCompare show); ReadOptions::scan_index (0-based position in /data3D) or ReadOptions::scan_name
// (the scan's `name`) selects one. images2D and all other metadata are ignored.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "k4reg/io/cloud_io.h"
#include "k4reg/geometry/point_cloud.h"

namespace k4reg {

PointCloud read_e57(const std::string& path, const ReadOptions& options = {});
PointCloud read_e57_bytes(std::string_view data, const std::string& name, const ReadOptions& options = {});
// The number of /data3D entries (the XML is parsed, no point is decoded).
std::size_t count_e57_scans(std::string_view data, const std::string& name);

// How the writer stores coordinates.
enum class E57Coordinates {
  kCartesianDouble,         // cartesianX/Y/Z as Float double
  kCartesianSingle,         // Float single: loses precision far from the scan frame's origin
  kCartesianScaledInteger,  // ScaledInteger: scale = resolution_m, offset = the cloud's origin_m, bit-packed
  kSphericalDouble,         // sphericalRange/Azimuth/Elevation as Float double, about the scan frame's origin
};

struct E57WriteOptions {
  E57Coordinates coordinates = E57Coordinates::kCartesianDouble;
  double resolution_m = 0.0001;  // kCartesianScaledInteger
  // Intensity (when the cloud has it): 0 = Float single with intensityLimits = the values' range; 1–32 = an
  // Integer field of that many bits, the values' range mapped linearly onto 0 … 2^bits − 1.
  int intensity_bits = 0;
};

// One scan to write (one /data3D entry).
struct E57Scan {
  std::string name;
  PointCloud cloud;  // in the scan's own frame
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // scan frame -> file frame
  // Empty, or one per point: 0 valid, 1 direction only, 2 no return (written as the invalid-state field of the
  // coordinates; such points keep their coordinates, which readers ignore).
  std::vector<std::uint8_t> invalid_state;
};

// Writes the scans with their names and poses, one CompressedVector binary section each (data packets of up to
// 64 KiB), then the XML, all in CRC-checked pages.
void write_e57(const std::string& path, const std::vector<E57Scan>& scans, const E57WriteOptions& options = {});

}  // namespace k4reg
