// The terrestrial laser scanner: constant angular sampling over 360 deg x 150 deg (elevation -60 to
// +90 deg; the cone below the tripod is blind), so the point density on a surface falls off with the
// square of the range as in a real TLS. A station with a look_at_m is an object range scanner instead:
// a square camera-like grid of rays over its field of view, aimed at that point. Each return has Gaussian range noise and an intensity from the
// surface's reflectivity, the incidence angle and a mild range attenuation; grazing and dark hits drop
// out, glass mostly transmits, foliage is half transparent.
//
// The scan is returned in its own frame: the scene frame rotated by a random rotation (uniform on
// SO(3) apart from excluding the ~1% within 10 deg of "up", so no scan keeps the scene's vertical)
// and translated so the scanner is at the origin (ScanFrame::kScanner), or then shifted by a random
// translation of up to 30 m per axis (kArbitrary: a scan exported in project coordinates, cropped and
// re-saved or moved by another tool, whose file says nothing of where its scanner stood).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <optional>

#include "k4reg/geometry/point_cloud.h"
#include "sim/scene.h"

namespace k4reg::sim {

enum class ScanFrame { kScanner, kArbitrary };

struct ScanParams {
  // Points wanted. The angular step is chosen so that rays x (hit fraction of a coarse pilot scan from
  // the same station) = points, so the result lands within a few per cent of this.
  std::size_t points = 0;                // 0 = the scene's default (700000 for the terrestrial scenes)
  std::uint64_t seed = 1;                // reproduces the scan bit for bit, for any thread count
  std::optional<double> noise_m;         // range noise standard deviation; unset = the scene's default
  double max_range_m = 0;                // 0 = the scene's default
  ScanFrame frame = ScanFrame::kScanner;  // the same points either way, only the frame differs
};

constexpr double kArbitraryShiftM = 30.0;  // kArbitrary: the translation's reach per axis

struct SimulatedScan {
  k4reg::PointCloud cloud;          // scan frame, with intensity in [0, 1] if the scene records it
  Eigen::Matrix4d scan_to_scene;    // ground truth: maps scan points into the scene frame
  Eigen::Vector3d station_m;        // scanner position in the scene frame
  double step_rad = 0.0;            // angular step, the same horizontally and vertically
  std::size_t rays = 0;             // rays cast (points / rays = the hit fraction)
};

// Throws k4reg::Error(kInvalidArgument) for a station out of range, fewer than 1000 or more than
// 50 million points, or a negative / non-finite noise or range.
SimulatedScan simulate_scan(const Scene& scene, int station, const ScanParams& params);

}  // namespace k4reg::sim
