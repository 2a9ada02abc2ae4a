// k4reg-simulate: writes a simulated terrestrial laser scan of an analytic scene and its ground truth.
//   k4reg-simulate --scene lab --station 0 --points 700000 --seed 1 [--frame arbitrary] --out scan.ply --gt scan.gt.txt
//   k4reg-simulate --list [--layout 3]
#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <numbers>
#include <string>

#include "k4reg/io/cloud_io.h"
#include "k4reg/util/error.h"
#include "k4reg/io/matrix_file.h"
#include "sim/scanner.h"
#include "sim/scene.h"

namespace {

// Lab and arch exist only as layout 0; a listing of another layout skips them.
void list_scenes(int layout) {
  for (const auto& name : k4reg::sim::scene_names()) {
    if (layout > 0 && (name == "lab" || name == "arch")) continue;
    const auto scene = k4reg::sim::make_scene(name, layout);
    std::printf("%s (layout %d): %s (defaults: %zu points, noise %.2f mm, max range %.0f m%s)\n", name.c_str(), layout,
                scene.description.c_str(), scene.default_points, scene.default_noise_m * 1000.0, scene.default_max_range_m,
                scene.intensity ? "" : ", no intensity");
    for (std::size_t i = 0; i < scene.stations.size(); ++i) {
      const auto& s = scene.stations[i];
      std::printf("  %s %zu  at (%7.2f, %7.2f, %6.2f) m  %s\n", name.c_str(), i, s.position_m.x(), s.position_m.y(),
                  s.position_m.z(), s.description.c_str());
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Simulates a terrestrial laser scan of an analytic scene, in a randomly rotated scanner frame, "
               "and writes the ground-truth transform (scan -> scene) next to it."};
  std::string scene_name, out_path, gt_path;
  int station = 0, layout = 0;
  k4reg::sim::ScanParams params;
  double noise_mm = 0.0;   // used only if given; else the scene's default
  long long points = 0;    // signed, so "-5" is refused instead of wrapping; 0 = the scene's default
  bool list = false;
  app.add_flag("--list", list, "print the scenes and their stations (of --layout), then exit");
  app.add_option("--scene", scene_name, "scene name (see --list)");
  app.add_option("--layout", layout,
                 "scene variant: 0 = canonical, N > 0 = a deterministic variant (not for lab and arch, which have only 0)")
      ->capture_default_str();
  app.add_option("--station", station, "station index (see --list)")->capture_default_str();
  app.add_option("--points", points, "number of points wanted (>= 1000; reached within a few %; 0 = the scene's default)")
      ->capture_default_str();
  app.add_option("--seed", params.seed, "random seed; the same seed reproduces the files bit for bit")->capture_default_str();
  const CLI::Option* noise_option = app.add_option("--noise-mm", noise_mm, "range noise standard deviation, mm (default: the scene's, see --list)");
  app.add_option("--max-range-m", params.max_range_m, "maximum range, m (0 = the scene's default)")->capture_default_str();
  app.add_option("--out", out_path, "scan file (.ply, .pcd, .xyz ...; format from the extension)");
  std::string frame = "scanner";
  app.add_option("--frame", frame,
                 "the scan's frame: scanner (the scanner at the origin) or arbitrary (then shifted by up to 30 m per "
                 "axis, as a scan exported in project coordinates)")
      ->check(CLI::IsMember({"scanner", "arbitrary"}))
      ->capture_default_str();
  app.add_option("--gt", gt_path, "ground-truth file: the 4x4 matrix mapping scan points into the scene frame");
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);  // --help
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "k4reg-simulate: %s\n", e.what());
    return 2;
  }

  try {
    if (list) {
      list_scenes(layout);
      return 0;
    }
    if (scene_name.empty() || out_path.empty() || gt_path.empty())
      k4reg::fail(k4reg::ErrorCode::kInvalidArgument, "--scene, --out and --gt are required (or --list)");
    if (points != 0 && points < 1000)
      k4reg::fail(k4reg::ErrorCode::kInvalidArgument, "--points must be at least 1000 (or 0), not " + std::to_string(points));
    params.points = static_cast<std::size_t>(points);
    params.frame = frame == "arbitrary" ? k4reg::sim::ScanFrame::kArbitrary : k4reg::sim::ScanFrame::kScanner;
    if (noise_option->count() > 0) {
      if (!(noise_mm >= 0.0 && noise_mm <= 1000.0))
        k4reg::fail(k4reg::ErrorCode::kInvalidArgument, "--noise-mm must be between 0 and 1000, not " + std::to_string(noise_mm));
      params.noise_m = noise_mm / 1000.0;
    }
    if (!(params.max_range_m >= 0.0))
      k4reg::fail(k4reg::ErrorCode::kInvalidArgument, "--max-range-m must be >= 0 (0 = the scene's default)");
    k4reg::format_from_extension(out_path);  // fail before tracing, not after
    const auto start = std::chrono::steady_clock::now();
    const auto scene = k4reg::sim::make_scene(scene_name, layout);
    const auto scan = k4reg::sim::simulate_scan(scene, station, params);
    const auto traced = std::chrono::steady_clock::now();
    k4reg::write_cloud(out_path, scan.cloud);
    k4reg::write_matrix4(gt_path, scan.scan_to_scene);
    const auto done = std::chrono::steady_clock::now();
    std::printf("%s layout %d station %d: %zu points from %zu rays (step %.4f deg), traced in %.2f s, written in %.2f s -> %s, %s\n",
                scene_name.c_str(), layout, station, scan.cloud.size(), scan.rays, scan.step_rad * 180.0 / std::numbers::pi,
                std::chrono::duration<double>(traced - start).count(), std::chrono::duration<double>(done - traced).count(),
                out_path.c_str(), gt_path.c_str());
  } catch (const k4reg::Error& e) {
    std::fprintf(stderr, "k4reg-simulate: %s\n", e.what());
    return 1;
  }
  return 0;
}
