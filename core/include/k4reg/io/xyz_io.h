// Plain-text point lists: .xyz / .txt / .csv / .pts / .asc / .3d (3DTK). See cloud_io.h for the common contract.
//
// One point per line: `x y z [intensity] [more columns…]`, separated by whitespace and/or commas.
// - Blank lines and comment lines starting with '#' or '//' are skipped.
// - A line holding a single integer is a point-count line (Leica PTS; also between scans of a
//   multi-scan PTS file) and is skipped.
// - A first line `W x H` (3DTK's .3d scans: the sweep's columns and rows) is skipped.
// - One header line made only of non-numeric words (e.g. "x,y,z,intensity") is skipped if it is the
//   first non-comment line; anywhere else a non-numeric token is an error naming the line.
// - All data lines must have the same number of columns (the first data line decides); a mismatch is an
//   error naming the line, rather than silently mixing points with and without intensity.
// - With 4 or more columns the 4th is intensity (PTS order x y z intensity r g b). Note: a bare
//   `x y z r g b` file therefore yields r as "intensity".
// - NaN/Inf coordinates are an error naming the line and point index.
#pragma once

#include <string>
#include <string_view>

#include "k4reg/io/cloud_io.h"
#include "k4reg/geometry/point_cloud.h"

namespace k4reg {

enum class XyzStyle {
  kSpace,    // "x y z [intensity]"
  kComma,    // "x,y,z[,intensity]"
  kPtsCount  // first line = point count, then "x y z [intensity]" (Leica PTS)
};

PointCloud read_xyz(const std::string& path, const ReadOptions& options = {});
PointCloud read_xyz_bytes(std::string_view data, const std::string& name, const ReadOptions& options = {});

// Coordinates: shortest exact float text when origin_m is zero, otherwise the world coordinate in double
// with 6 decimals (µm at survey coordinates). Intensity: shortest exact float text.
void write_xyz(const std::string& path, const PointCloud& cloud, XyzStyle style = XyzStyle::kSpace);

}  // namespace k4reg
