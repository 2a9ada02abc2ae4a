// k4reg-bench-read: read throughput of every scan format on one 10 M-point cloud at UTM coordinates.
//
// The cloud (random points with intensity in a 200 m x 200 m x 30 m block at 500 000 E / 5 240 000 N) is written
// by the core's writers into a temporary folder — binary PLY (the baseline), LAS 1.4 point format 6, PTX (one
// 2500 x 4000 scan), E57 with Float double and with ScaledInteger (0.1 mm) coordinates — and each file is read
// with read_cloud: once to load the page cache, then `--repeats` times; the median is reported. Prints a markdown
// table (bench/run.sh puts it into bench/RESULTS.md).
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "k4reg/io/cloud_io.h"
#include "k4reg/io/e57_io.h"
#include "k4reg/io/las_io.h"
#include "k4reg/io/ply_io.h"
#include "k4reg/io/ptx_io.h"
#include "k4reg/util/stopwatch.h"

namespace fs = std::filesystem;
using k4reg::seconds_since;
using k4reg::SteadyClock;

namespace {

k4reg::PointCloud survey_cloud(std::size_t n) {
  k4reg::PointCloud cloud;
  cloud.origin_m = Eigen::Vector3d(500100.0, 5240100.0, 300.0);
  cloud.points.resize(n);
  cloud.intensity.resize(n);
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> xy(-100.0f, 100.0f), z(-15.0f, 15.0f), intensity(0.0f, 1.0f);
  for (std::size_t i = 0; i < n; ++i) {
    cloud.points[i] = Eigen::Vector3f(xy(rng), xy(rng), z(rng));
    cloud.intensity[i] = intensity(rng);
  }
  return cloud;
}

struct Format {
  const char* name;
  const char* file;
  std::function<void(const std::string&, const k4reg::PointCloud&)> write;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("k4reg-bench-read: read throughput (points/s) of PLY, LAS, PTX and E57 files");
  std::size_t points = 10'000'000;
  int repeats = 3;
  std::string dir = fs::temp_directory_path().string();
  app.add_option("--points", points, "points in the cloud")->check(CLI::Range(std::size_t{1000}, std::size_t{100'000'000}));
  app.add_option("--repeats", repeats, "timed reads per file (median reported)")->check(CLI::Range(1, 20));
  app.add_option("--dir", dir, "where the temporary files go")->check(CLI::ExistingDirectory);
  CLI11_PARSE(app, argc, argv);

  const k4reg::PointCloud cloud = survey_cloud(points);
  const std::vector<Format> formats = {
      {"PLY binary (float64 x y z, float intensity)", "cloud.ply",
       [](const std::string& p, const k4reg::PointCloud& c) { k4reg::write_ply(p, c); }},
      {"LAS 1.4, point format 6", "cloud.las", [](const std::string& p, const k4reg::PointCloud& c) { k4reg::write_las(p, c); }},
      {"PTX, one 2500 x 4000 scan", "cloud.ptx",
       [](const std::string& p, const k4reg::PointCloud& c) {
         std::vector<k4reg::PtxScan> scans(1);
         scans[0].cloud = c;
         scans[0].columns = c.size() % 2500 == 0 ? 2500 : 0;
         k4reg::write_ptx(p, scans);
       }},
      {"E57, Float double coordinates", "double.e57",
       [](const std::string& p, const k4reg::PointCloud& c) {
         k4reg::E57Scan scan;
         scan.cloud = c;
         k4reg::write_e57(p, {scan});
       }},
      {"E57, ScaledInteger coordinates (0.1 mm)", "scaled.e57",
       [](const std::string& p, const k4reg::PointCloud& c) {
         k4reg::E57Scan scan;
         scan.cloud = c;
         k4reg::E57WriteOptions options;
         options.coordinates = k4reg::E57Coordinates::kCartesianScaledInteger;
         k4reg::write_e57(p, {scan}, options);
       }},
  };

  std::printf("| format | file MB | write s | read s (median of %d) | M points/s |\n|---|---|---|---|---|\n", repeats);
  for (const Format& format : formats) {
    const std::string path = (fs::path(dir) / (std::string("k4reg-bench-read-") + format.file)).string();
    auto start = SteadyClock::now();
    format.write(path, cloud);
    const double write_s = seconds_since(start);
    std::size_t read_points = k4reg::read_cloud(path).size();  // loads the page cache
    std::vector<double> times;
    for (int r = 0; r < repeats; ++r) {
      start = SteadyClock::now();
      read_points = k4reg::read_cloud(path).size();
      times.push_back(seconds_since(start));
    }
    std::sort(times.begin(), times.end());
    const double median = times[times.size() / 2];
    std::printf("| %s | %.0f | %.2f | %.2f | %.1f |\n", format.name, fs::file_size(path) / 1e6, write_s, median,
                read_points / median / 1e6);
    std::fflush(stdout);
    fs::remove(path);
    if (read_points != points) {
      std::fprintf(stderr, "%s: read %zu points, wrote %zu\n", format.file, read_points, points);
      return 1;
    }
  }
  return 0;
}
