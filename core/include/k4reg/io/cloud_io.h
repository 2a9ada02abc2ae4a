// Point-cloud file I/O: one interface over every supported format — PLY (ply_io.h), PCD (pcd_io.h), text
// XYZ/TXT/CSV/PTS (xyz_io.h), LAS 1.0–1.4 (las_io.h; LAZ is refused), PTX (ptx_io.h) and E57 (e57_io.h).
//
// Reading: every reader maps the file, validates the header against the file size *before* allocating,
// parses coordinates in double precision and builds the cloud with make_local_cloud() (survey coordinates
// are shifted to a local origin before anything becomes float). Every problem — missing file, empty file,
// wrong magic, malformed/truncated header or body, NaN/Inf coordinates, no points — is a k4reg::Error whose
// message starts with the file name ("scan.ply: truncated: …"). Readers never crash on hostile input, and their
// memory stays a small multiple of the file's size whatever a header claims (io_common.h: kMaxTokensPerLine,
// kMaxHeaderEntries).
//
// Error codes: kNotFound (file missing), kInvalidArgument (malformed / truncated / empty / NaN / 0 points / LAZ),
// kResourceExhausted (more points than ReadOptions::max_points; refused before allocating),
// kDataLoss (a page of an E57 file fails its CRC-32C), kPermissionDenied (cannot open or write for permission
// reasons).
//
// Writing: world coordinates (origin_m + point, in double) are written. PLY and PCD store float32 when
// origin_m is zero and float64 otherwise, LAS scaled integers with offset = origin_m, E57 doubles, so survey
// coordinates survive a round trip.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include "k4reg/geometry/point_cloud.h"

namespace k4reg {

// Never rely on the numeric values.
enum class CloudFormat { kPly, kPcd, kXyz, kLas, kPtx, kE57 };

const char* to_string(CloudFormat format);

struct ReadOptions {
  // 0 = unlimited. A file holding more points is refused with kResourceExhausted before any allocation
  // (for formats with a point count in the header) or as soon as the limit is passed (XYZ text).
  std::size_t max_points = 0;
  // Multi-scan formats (E57, PTX): neither set = every scan, merged in the file's common frame (each scan's
  // pose / matrix applied); scan_index (0-based) or scan_name (E57 only) = that scan alone, still in the
  // common frame. Setting either for a single-scan format is kInvalidArgument.
  std::optional<std::size_t> scan_index = std::nullopt;
  std::string scan_name = {};
  // Multi-scan formats: false = each selected scan in its own scanner frame (its E57 pose or PTX matrix not
  // applied), as a project registers it; other formats ignore it.
  bool apply_pose = true;
};

// Format by content (magic bytes: "ply\n"; "LASF"; "ASTM-E57"; PCD header starting "# .PCD", "VERSION" or
// "FIELDS"; a PTX scan header = two integer lines, then lines of 3 and 4 numbers; other numeric text → XYZ), with
// the extension as a hint when the content is not conclusive (a ".ply" file without the magic is reported by the
// PLY reader as "wrong magic"; ".laz" goes to the LAS reader, which refuses LAZ). kNotFound if the file is
// missing, kInvalidArgument if the format cannot be determined.
CloudFormat detect_format(const std::string& path);

// Same rules on an in-memory buffer (e.g. uploaded bytes); `name` gives the extension hint and is used in
// error messages.
CloudFormat detect_format_bytes(std::string_view data, const std::string& name);

// Format from the extension only (.ply, .pcd, .xyz/.txt/.pts/.csv/.asc/.3d, .las, .ptx, .e57; case-insensitive).
// kInvalidArgument for anything else, and for .laz ("LAZ is not supported; decompress with laszip or pdal
// first").
CloudFormat format_from_extension(const std::string& path);

PointCloud read_cloud(const std::string& path, const ReadOptions& options = {});

// How many scans the file holds: /data3D entries of an E57 file, scans of a PTX file (read through, points
// unparsed), 1 for every other format. Throws as read_cloud for a file that is not a readable cloud.
std::size_t count_scans(const std::string& path);

// Reads a cloud from bytes already in memory (uploads). `name` is used for the format hint and messages.
PointCloud read_cloud_bytes(std::string_view data, const std::string& name, const ReadOptions& options = {});

// Format from the extension: .ply → binary little-endian PLY, .pcd → binary PCD, .xyz/.txt/.csv/.pts →
// ASCII text (".pts" gets a leading point-count line, ".csv" comma separators), .las → LAS 1.4 point format 6
// (0.1 mm resolution), .ptx → one PTX scan (identity matrix, one row), .e57 → one E57 scan (Float double
// coordinates, identity pose). The file is written to a temporary name next to `path` and renamed, so readers
// never see a half-written file.
void write_cloud(const std::string& path, const PointCloud& cloud);

}  // namespace k4reg
