// k4reg-bench-scanner: how far the scanner position estimated from a scan's sampling (scanner_position.h) lies from
// the truth, on simulated stations in arbitrary frames (a random rotation and a translation of up to 30 m per axis)
// and on real scans, split into a tuning part and a held-out part; and that clouds with no single scanner (two scans
// merged, a voxel-subsampled scan) get none.
//
//   k4reg-bench-scanner [--part tuning|held-out|all] [--data-dir DIR] [--cache-dir DIR] [--points N] [--csv FILE]
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "k4reg/geometry/sampling.h"
#include "k4reg/geometry/voxel_grid.h"
#include "k4reg/io/cloud_io.h"
#include "k4reg/registration/scanner_position.h"
#include "k4reg/registration/scanner_sampling.h"
#include "random_motion.h"
#include "simulated_scan_cache.h"

namespace fs = std::filesystem;

namespace k4reg::bench {
namespace {

struct Case {
  std::string name, part, kind;  // kind: "station" (a scanner to find), "merged" or "resampled" (none to find)
  PointCloud cloud;
  std::optional<Eigen::Vector3d> scanner_m;  // truth, in the cloud's file frame
};

struct Outcome {
  bool found = false;
  double error_m = -1, share = 0, step_rad = 0, seconds = 0;
};

Outcome run(const Case& c) {
  const auto start = std::chrono::steady_clock::now();
  const Sampling sampling = measure_sampling(c.cloud);
  const NeighbourAngles angles(c.cloud.points, sampling.spacing_m);
  const ScannerEstimate estimate = estimate_scanner_position(angles);
  Outcome o;
  o.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  o.found = estimate.found;
  o.share = estimate.fit.share;
  o.step_rad = estimate.fit.step_rad;
  if (c.scanner_m) o.error_m = (c.cloud.origin_m + estimate.position_m.cast<double>() - *c.scanner_m).norm();
  return o;
}

// A simulated station moved into an arbitrary frame: its scanner, at the scan frame's origin, moves with it.
Case station(const std::string& cache_dir, const std::string& scene, int layout, int station_index,
             std::size_t points, const std::string& part, std::uint64_t seed) {
  const CachedScan scan = cached_simulated_scan(cache_dir, scene, station_index, points, layout);
  const Eigen::Matrix4d motion = random_motion(seed, 30.0);
  Case c{fmt::format("{}-l{}-s{}", scene, layout, station_index), part, "station",
         moved(read_cloud(scan.path), motion), motion.topRightCorner<3, 1>()};
  return c;
}

}  // namespace
}  // namespace k4reg::bench

int main(int argc, char** argv) {
  using namespace k4reg;
  using namespace k4reg::bench;
  CLI::App app{"Scanner positions estimated from the scans' sampling, against the truth"};
  std::string part = "all", data_dir = "../shared/data", cache_dir = "bench/cache", csv_path;
  std::size_t points = 700000;
  app.add_option("--part", part, "tuning, held-out or all")->check(CLI::IsMember({"tuning", "held-out", "all"}));
  app.add_option("--data-dir", data_dir, "the real data sets");
  app.add_option("--cache-dir", cache_dir, "simulated scans are cached here");
  app.add_option("--points", points, "points per simulated scan");
  app.add_option("--csv", csv_path, "one line per case");
  CLI11_PARSE(app, argc, argv);

  std::vector<std::function<Case()>> cases;
  auto add = [&](const std::string& case_part, std::function<Case()> make) {
    if (part == "all" || part == case_part) cases.push_back(std::move(make));
  };
  // Tuning: the lab and hall layout 0-1. Held out: other layouts and scenes, and every real scan.
  for (int s = 0; s < 4; ++s) add("tuning", [&, s] { return station(cache_dir, "lab", 0, s, points, "tuning", 100 + s); });
  for (int l = 0; l < 2; ++l)
    for (int s = 0; s < 4; ++s)
      add("tuning", [&, l, s] { return station(cache_dir, "hall", l, s, points, "tuning", 200 + 10 * l + s); });
  for (const std::string scene : {"courtyard", "corridor", "arch"})
    for (int s = 0; s < 3; ++s)
      add("held-out", [&, scene, s] { return station(cache_dir, scene, scene == "arch" ? 0 : 1, s, points, "held-out", 300 + s); });
  for (int s = 0; s < 4; ++s)
    add("held-out", [&, s] { return station(cache_dir, "hall", 5, s, points, "held-out", 400 + s); });
  // No single scanner: two stations merged; one voxel-subsampled at 5 cm.
  add("held-out", [&] {
    // Two stations registered into the scene's frame and merged, as a merged export would be.
    std::vector<Eigen::Vector3d> all;
    for (const int s : {1, 2}) {
      const CachedScan scan = cached_simulated_scan(cache_dir, "lab", s, points);
      const PointCloud cloud = read_cloud(scan.path);
      for (const auto& p : cloud.points)
        all.push_back(scan.scan_to_scene.topLeftCorner<3, 3>() * (cloud.origin_m + p.cast<double>()) +
                      scan.scan_to_scene.topRightCorner<3, 1>() + Eigen::Vector3d(12.0, -7.0, 3.0));
    }
    return Case{"lab-merged-s1-s2", "held-out", "merged", make_local_cloud(all, {}), std::nullopt};
  });
  add("held-out", [&] {
    Case a = station(cache_dir, "hall", 5, 0, points, "held-out", 501);
    PointCloud thinned = voxel_grid(a.cloud, 0.05).cloud;
    thinned.origin_m = a.cloud.origin_m;
    return Case{"hall-l5-s0-voxel5cm", "held-out", "resampled", thinned, std::nullopt};
  });
  // Real scans in their scanners' frames, moved arbitrarily.
  const fs::path data(data_dir);
  auto real = [&](const std::string& name, const fs::path& file, double scale, std::uint64_t seed) {
    add("held-out", [=] {
      PointCloud cloud = read_cloud(file.string());
      const Eigen::Matrix4d motion = random_motion(seed, 30.0 * scale);
      return Case{name, "held-out", "station", moved(cloud, motion), motion.topRightCorner<3, 1>()};
    });
  };
  real("kurt3d-scan000 (cm)", data / "3dtk-kurt3d-scans/derived/scan000.ply", 100.0, 600);
  real("kurt3d-scan001 (cm)", data / "3dtk-kurt3d-scans/derived/scan001.ply", 100.0, 601);
  real("velodyne-251370668", data / "velodyne-pair-fastgicp/251370668.pcd", 1.0, 602);
  real("velodyne-251371071", data / "velodyne-pair-fastgicp/251371071.pcd", 1.0, 603);
  add("held-out", [=] {
    return Case{"3dmatch-fragment-ref (fused RGB-D)", "held-out", "merged",
                read_cloud((data / "3dmatch-pair-geotransformer/derived/ref.ply").string()), std::nullopt};
  });

  std::ofstream csv;
  if (!csv_path.empty()) {
    csv.open(csv_path);
    csv << "case,part,kind,found,error_m,fit,step_rad,seconds\n";
  }
  std::printf("%-36s %-8s %-9s %-5s %9s %7s %7s %6s\n", "case", "part", "kind", "found", "error", "fit", "step",
              "s");
  for (const auto& make : cases) {
    const Case c = make();
    const Outcome o = run(c);
    std::printf("%-36s %-8s %-9s %-5s %9.3f %7.3f %7.5f %6.2f\n", c.name.c_str(), c.part.c_str(), c.kind.c_str(),
                o.found ? "yes" : "no", o.error_m, o.share, o.step_rad, o.seconds);
    std::fflush(stdout);
    if (csv.is_open())
      csv << fmt::format("{},{},{},{},{:.4f},{:.4f},{:.4f},{:.3f}\n", c.name, c.part, c.kind, o.found, o.error_m,
                         o.share, o.step_rad, o.seconds);
  }
  return 0;
}
