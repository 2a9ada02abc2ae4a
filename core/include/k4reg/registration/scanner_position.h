// Where a terrestrial scan's scanner stood, from the scan itself. A scanner samples at a constant angular step:
// seen from where it stood, a point and its nearest neighbour lie one step apart in angle (or the step times the
// cosine of the elevation, between two profiles away from the horizon), whatever their range, the surface's
// incidence or the range noise. Seen from anywhere else, near points' neighbours subtend large angles and far
// points' small ones. So the scanner is the point from which most neighbour pairs subtend one and the same angle.
// This is what the free-space evidence (free_space.h) needs when a file's frame is not the scanner's: a scan
// exported in project coordinates, cropped, shifted or moved by another tool keeps its sampling, not its origin.
// A cloud with no single constant-angle sampling (merged scans, a voxel-subsampled or meshed cloud) has no such
// point: its neighbour angles stay spread from everywhere, and no position is given.
// The search itself is in scanner_sampling.h.
// Cost: nearest neighbours of 4096 sampled points, then (unless the declared position fits) the search: about
// 0.5-1.5 s for 1 M points; once per scan (PreparedScan::scanner).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "k4reg/geometry/point_cloud.h"
#include "k4reg/util/cancellation.h"

namespace k4reg {

// Where a scan's scanner position comes from.
enum class ScannerSource {
  kNone,       // unknown: nothing in the file or the data says where a single scanner stood
  kOrigin,     // the file frame's origin (a scan in its scanner's frame), confirmed by the data where they can
  kFile,       // the file says it (an E57 scan's pose, a PTX scan's scanner registration)
  kEstimated,  // found from the scan's sampling (estimate_scanner_position)
};
const char* to_string(ScannerSource source);
// The source a to_string name stands for; kNone for any other text.
ScannerSource scanner_source_named(const std::string& name);

// What the data say about one candidate scanner position: how many neighbouring points lie one angular step apart
// seen from there.
struct SamplingFit {
  double share = 0.0;     // of the sampled neighbour pairs, those within 3 % of the commonest angle (measured,
                          // k4reg-bench-scanner): 0.72-0.83 at the scanner of a simulated scan, 0.67-0.68 of real
                          // ones (Kurt3D), 0.49 or less at wrong positions, 0.01-0.12 for merged, voxelised, fused
                          // or multi-beam clouds; a scanner needs 0.5
  double step_rad = 0.0;  // that angle: the scanner's angular step (or its horizontal step times the cosine of the
                          // elevation it is seen at most often), if it stood there
};

// Whether `at` could be a terrestrial scanner of these points: inside their bounding box, with half of them
// a metre or more away (in the points' units). An object seen by a range camera from outside, or a frame origin
// at a map datum kilometres away, is not.
bool surrounded_by(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& at);
// Whether any position could be surrounded by the points: inside their bounding box every range is at most its
// diagonal, so a cloud whose diagonal is under a scanner's least median range (an object) surrounds none, and its
// scanner is not searched for (the search costs ~1 s even on a 40 k-point view).
bool could_surround_a_scanner(const std::vector<Eigen::Vector3f>& points);

// A scan's scanner position, and where it comes from.
struct ScannerPosition {
  ScannerSource source = ScannerSource::kNone;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();  // in the file's frame (none: zero)
  SamplingFit fit;     // the scan's sampling seen from there (for none: from the best position found)
  std::string reason;  // how it was decided, or why none, in words
};

// Where the scan's scanner stood: where the file declares it (cloud.scanner_m, else the frame's origin) where that
// could be a scanner's (surrounded_by) and the sampling does not point clearly elsewhere; else the estimate from
// the sampling; else none. spacing_m: the cloud's point spacing (sampling.h). Cost: estimate_scanner_position's,
// unless the file says it or the origin fits.
ScannerPosition locate_scanner(const PointCloud& cloud, double spacing_m, const CancellationToken* cancel = nullptr);

}  // namespace k4reg
