// Centroid voxel grid: k4reg::voxel_grid (TBB, all cores; and on one thread, for a per-core comparison)
// against pcl::VoxelGrid<PointXYZI> (single-threaded) on one simulated 10 M-point lab scan, at the
// paper's 50 mm and 100 mm spacings.
// The PCL cloud is built once beforehand, so PCL is timed without any conversion; the conversion has
// its own benchmark. Counters: output points, and pcl_grid_cells: PCL's VoxelGrid refuses grids of more
// than INT32_MAX cells (it warns and returns its input unfiltered).
#include <benchmark/benchmark.h>
#include <pcl/filters/voxel_grid.h>
#include <tbb/task_arena.h>

#include "k4reg/geometry/voxel_grid.h"
#include "pcl_methods.h"
#include "sim/scanner.h"
#include "sim/scene.h"

namespace {

constexpr std::size_t kScanPoints = 10'000'000;

// Simulated once for all benchmarks (about 3 s): the lab's south-west station.
const k4reg::PointCloud& lab_scan() {
  static const k4reg::PointCloud cloud = [] {
    k4reg::sim::ScanParams params;
    params.points = kScanPoints;
    params.seed = 1;
    return k4reg::sim::simulate_scan(k4reg::sim::make_scene("lab"), 0, params).cloud;
  }();
  return cloud;
}

const k4reg::bench::PclCloud::Ptr& lab_scan_pcl() {
  static const k4reg::bench::PclCloud::Ptr cloud = k4reg::bench::to_pcl(lab_scan());
  return cloud;
}

double leaf_m(const benchmark::State& state) { return state.range(0) / 1000.0; }

void BM_OursVoxelGrid(benchmark::State& state) {
  const k4reg::PointCloud& cloud = lab_scan();
  std::size_t out = 0;
  for (auto _ : state) {
    const k4reg::VoxelizedCloud voxels = k4reg::voxel_grid(cloud, leaf_m(state));
    out = voxels.cloud.size();
    benchmark::DoNotOptimize(voxels.cloud.points.data());
  }
  state.counters["points_in"] = static_cast<double>(cloud.size());
  state.counters["points_out"] = static_cast<double>(out);
}

void BM_OursVoxelGridOneThread(benchmark::State& state) {
  tbb::task_arena one_thread(1);
  one_thread.execute([&] { BM_OursVoxelGrid(state); });
}

void BM_PclVoxelGrid(benchmark::State& state) {
  const auto& cloud = lab_scan_pcl();
  const float leaf = static_cast<float>(leaf_m(state));
  std::size_t out = 0;
  for (auto _ : state) {
    pcl::VoxelGrid<pcl::PointXYZI> grid;
    grid.setLeafSize(leaf, leaf, leaf);
    grid.setInputCloud(cloud);
    k4reg::bench::PclCloud filtered;
    grid.filter(filtered);
    out = filtered.size();
    benchmark::DoNotOptimize(filtered.data());
  }
  state.counters["points_in"] = static_cast<double>(cloud->size());
  state.counters["points_out"] = static_cast<double>(out);
  state.counters["pcl_grid_cells"] = static_cast<double>(k4reg::bench::pcl_voxel_grid_cells(*cloud, leaf_m(state)));
}

// What feeding PCL from our cloud type costs on top (not part of BM_PclVoxelGrid).
void BM_ConvertToPcl(benchmark::State& state) {
  const k4reg::PointCloud& cloud = lab_scan();
  for (auto _ : state) {
    const auto converted = k4reg::bench::to_pcl(cloud);
    benchmark::DoNotOptimize(converted->data());
  }
}

BENCHMARK(BM_OursVoxelGrid)->ArgName("leaf_mm")->Arg(50)->Arg(100)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_OursVoxelGridOneThread)->ArgName("leaf_mm")->Arg(50)->Arg(100)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_PclVoxelGrid)->ArgName("leaf_mm")->Arg(50)->Arg(100)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ConvertToPcl)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
