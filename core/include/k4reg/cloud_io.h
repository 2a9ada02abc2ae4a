// Point-cloud file I/O: one interface over every supported format.
//
// Reading: every reader maps the file, validates the header against the file size *before* allocating,
// parses coordinates in double precision and builds the cloud with make_local_cloud() (survey coordinates
// are shifted to a local origin before anything becomes float). Every problem — missing file, empty file,
// wrong magic, malformed/truncated header or body, NaN/Inf coordinates, no points — is a k4reg::Error whose
// message starts with the file name ("scan.ply: truncated: …"). Readers never crash on hostile input, and their
// memory stays a small multiple of the file's size whatever a header claims (io_common.h: kMaxTokensPerLine,
// kMaxHeaderEntries).
//
// Error codes: kNotFound (file missing), kInvalidArgument (malformed / truncated / empty / NaN / 0 points),
// kResourceExhausted (more points than ReadOptions::max_points; refused before allocating),
// kPermissionDenied (cannot open or write for permission reasons).
//
// Writing: world coordinates (origin_m + point, in double) are written. PLY and PCD store float32 when
// origin_m is zero and float64 otherwise, so survey coordinates survive a round trip.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "k4reg/point_cloud.h"

namespace k4reg {

// Room for more (LAS, PTX, E57 later): never rely on the numeric values.
enum class CloudFormat { kPly, kPcd, kXyz };

const char* to_string(CloudFormat format);

struct ReadOptions {
  // 0 = unlimited. A file holding more points is refused with kResourceExhausted before any allocation
  // (for formats with a point count in the header) or as soon as the limit is passed (XYZ text).
  std::size_t max_points = 0;
};

// Format by content (magic bytes: "ply\n"; PCD header starting "# .PCD", "VERSION" or "FIELDS";
// numeric text → XYZ), with the extension as a hint when the content is not conclusive (a ".ply" file
// without the magic is reported by the PLY reader as "wrong magic"). kNotFound if the file is missing,
// kInvalidArgument if the format cannot be determined.
CloudFormat detect_format(const std::string& path);

// Same rules on an in-memory buffer (e.g. uploaded bytes); `name` gives the extension hint and is used in
// error messages.
CloudFormat detect_format_bytes(std::string_view data, const std::string& name);

// Format from the extension only (.ply, .pcd, .xyz/.txt/.pts/.csv; case-insensitive).
// kInvalidArgument for anything else.
CloudFormat format_from_extension(const std::string& path);

PointCloud read_cloud(const std::string& path, const ReadOptions& options = {});

// Reads a cloud from bytes already in memory (uploads). `name` is used for the format hint and messages.
PointCloud read_cloud_bytes(std::string_view data, const std::string& name, const ReadOptions& options = {});

// Format from the extension: .ply → binary little-endian PLY, .pcd → binary PCD, .xyz/.txt/.csv/.pts →
// ASCII text (".pts" gets a leading point-count line, ".csv" comma separators). The file is written to a
// temporary name next to `path` and renamed, so readers never see a half-written file.
void write_cloud(const std::string& path, const PointCloud& cloud);

}  // namespace k4reg
