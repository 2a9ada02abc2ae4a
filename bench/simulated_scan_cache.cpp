#include "simulated_scan_cache.h"

#include <cstdint>
#include <cstdio>
#include <filesystem>

#include "k4reg/io/cloud_io.h"
#include "k4reg/io/matrix_file.h"
#include "sim/scanner.h"
#include "sim/scene.h"

namespace fs = std::filesystem;

namespace k4reg::bench {

CachedScan cached_simulated_scan(const std::string& cache_dir, const std::string& scene, int station,
                                 std::size_t points, int layout, sim::ScanFrame frame) {
  const std::uint64_t seed = static_cast<std::uint64_t>(station) + 1;
  const std::string variant = layout > 0 ? "-layout" + std::to_string(layout) : "";
  const std::string stem = cache_dir + "/" + scene + variant + "-station" + std::to_string(station) + "-" +
                           std::to_string(points) + "-seed" + std::to_string(seed) +
                           (frame == sim::ScanFrame::kArbitrary ? "-arbitrary" : "");
  const std::string gt_path = stem + ".gt.txt";
  CachedScan file{stem + ".ply", Eigen::Matrix4d::Identity()};
  if (!fs::exists(file.path) || !fs::exists(gt_path)) {
    std::printf("simulating %s layout %d station %d, %zu points ...\n", scene.c_str(), layout, station, points);
    std::fflush(stdout);
    fs::create_directories(cache_dir);
    sim::ScanParams params;
    params.points = points;
    params.seed = seed;
    params.frame = frame;
    const sim::SimulatedScan scan = sim::simulate_scan(sim::make_scene(scene, layout), station, params);
    write_cloud(file.path, scan.cloud);
    write_matrix4(gt_path, scan.scan_to_scene);
  }
  file.scan_to_scene = read_matrix4(gt_path);
  return file;
}

}  // namespace k4reg::bench
