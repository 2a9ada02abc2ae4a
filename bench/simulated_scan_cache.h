// Simulated scans cached on disk, shared by the benchmarks (k4reg-bench-compare, k4reg-bench-table2): a scan
// is simulated once per (scene, station, size) and written as PLY with its ground-truth pose next to it, so
// later runs (and the other benchmark) only read it.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <cstddef>
#include <string>

#include "sim/scanner.h"

namespace k4reg::bench {

struct CachedScan {
  std::string path;                // the PLY file
  Eigen::Matrix4d scan_to_scene;   // ground truth: scan frame -> scene frame
};

// The scan of `station` of the scene's `layout` with about `points` points (simulator seed = station + 1), in its
// scanner's frame or an arbitrary one, simulated into cache_dir on first use as
// <scene>[-layout<n>]-station<k>-<points>-seed<k+1>[-arbitrary].ply and .gt.txt.
// Throws k4reg::Error for an unknown scene, layout or station and for files that cannot be written or read.
CachedScan cached_simulated_scan(const std::string& cache_dir, const std::string& scene, int station,
                                 std::size_t points, int layout = 0, sim::ScanFrame frame = sim::ScanFrame::kScanner);

// T_target_source: maps source scan coordinates onto the target scan.
inline Eigen::Matrix4d source_to_target_truth(const CachedScan& source, const CachedScan& target) {
  return target.scan_to_scene.inverse() * source.scan_to_scene;
}

}  // namespace k4reg::bench
