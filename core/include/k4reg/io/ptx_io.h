// PTX (Leica Cyclone ASCII export) reader and writer. See cloud_io.h for the common contract.
//
// A PTX file holds one or several scans, each a header of 10 lines followed by columns × rows point lines:
//   columns
//   rows
//   scanner position (x y z)             } informative: the matrix below is what places the scan
//   scanner axes X, Y, Z (3 lines of 3)  }
//   4×4 matrix, 4 lines of 4: r11 r12 r13 0 / r21 r22 r23 0 / r31 r32 r33 0 / tx ty tz 1
//   x y z [intensity [r g b]]            (columns × rows lines, one per grid cell)
// The matrix is applied to row vectors (p' = p · M, translation in the last row): each point goes from the
// scanner's frame into the file's common (registered) frame. Lines "0 0 0 …" are cells without a return and
// are skipped. The 4th column is intensity (raw value; usually 0–1, older Cyclone exports −2048…2047); a scan
// whose intensity is constant (e.g. 0.5 everywhere) carries none, and when the selected scans do not all have
// intensity the cloud has none. Every scan's declared columns × rows is checked against the bytes left in the
// file before anything is allocated.
//
// Scans: all of them merged in the common frame by default; ReadOptions::scan_index picks one (0-based, still
// transformed by its matrix). PTX scans have no names: ReadOptions::scan_name is refused.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "k4reg/io/cloud_io.h"
#include "k4reg/geometry/point_cloud.h"

namespace k4reg {

PointCloud read_ptx(const std::string& path, const ReadOptions& options = {});
PointCloud read_ptx_bytes(std::string_view data, const std::string& name, const ReadOptions& options = {});
// The number of scans (headers parsed and point lines counted, not parsed).
std::size_t count_ptx_scans(std::string_view data, const std::string& name);

// True when the text starts like a PTX scan header (two integer lines, four lines of 3 numbers, four of 4).
bool looks_like_ptx(std::string_view data);

struct PtxScan {
  PointCloud cloud;  // points in the scanner's frame; a point at exactly (0, 0, 0) is a cell without a return
  Eigen::Matrix4d scanner_to_file = Eigen::Matrix4d::Identity();  // p_file = M * p_scanner (column vectors)
  std::size_t columns = 0;  // grid columns; 0 = one row holding every point. cloud.size() must be a multiple.
};

// Writes the scans in order: coordinates with 6 decimals (µm), intensity as the shortest exact float text (0 when
// the cloud has none), the matrix as the shortest exact double text. The scanner position and axes lines are
// taken from the matrix.
void write_ptx(const std::string& path, const std::vector<PtxScan>& scans);

}  // namespace k4reg
