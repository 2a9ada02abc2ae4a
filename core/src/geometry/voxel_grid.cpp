#include "k4reg/geometry/voxel_grid.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <string>

#include "k4reg/util/error.h"
#include "k4reg/geometry/hash_map.h"

namespace k4reg {
namespace {

// Fixed chunking (not per thread) keeps the floating-point summation order, and so the output,
// independent of the number of threads.
constexpr std::size_t kChunkPoints = 1 << 18;

struct Accumulator {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double intensity = 0.0;
  std::uint32_t count = 0;
};

struct Chunk {
  std::vector<std::uint64_t> keys;  // in first-seen order
  std::vector<Accumulator> voxels;
};

}  // namespace

VoxelizedCloud voxel_grid(const PointCloud& cloud, double voxel_m, const CancellationToken* cancel) {
  if (!(voxel_m > 0.0) || !std::isfinite(voxel_m))
    fail(ErrorCode::kInvalidArgument, "voxel size must be positive, got " + std::to_string(voxel_m));
  const float inv_voxel = static_cast<float>(1.0 / voxel_m);
  const bool with_intensity = cloud.has_intensity();
  const std::size_t n = cloud.size();
  const std::size_t chunk_count = (n + kChunkPoints - 1) / kChunkPoints;
  std::vector<Chunk> chunks(chunk_count);

  tbb::parallel_for(std::size_t{0}, chunk_count, [&](std::size_t c) {
    check(cancel);
    const std::size_t begin = c * kChunkPoints, end = std::min(n, begin + kChunkPoints);
    Chunk& chunk = chunks[c];
    VoxelKeyMap map((end - begin) / 4);
    for (std::size_t i = begin; i < end; ++i) {
      const Eigen::Vector3i index = voxel_index(cloud.points[i], inv_voxel);
      if ((index.array().abs() >= kVoxelAxisLimit).any())
        fail(ErrorCode::kInvalidArgument, "cloud extent too large for a " + std::to_string(voxel_m) +
                                              " m voxel grid (more than 2^21 voxels along an axis)");
      const std::uint64_t key = pack_voxel_key(index);
      bool inserted = false;
      const std::uint32_t slot = map.find_or_insert(key, static_cast<std::uint32_t>(chunk.keys.size()), inserted);
      if (inserted) {
        chunk.keys.push_back(key);
        chunk.voxels.emplace_back();
      }
      Accumulator& acc = chunk.voxels[slot];
      acc.sum += cloud.points[i].cast<double>();
      if (with_intensity) acc.intensity += cloud.intensity[i];
      ++acc.count;
    }
  });

  // Merge the chunks in order; scan order makes chunks spatially coherent, so this is cheap.
  VoxelKeyMap map(n / 8 + 16);
  std::vector<Accumulator> voxels;
  for (const Chunk& chunk : chunks) {
    check(cancel);
    for (std::size_t k = 0; k < chunk.keys.size(); ++k) {
      bool inserted = false;
      const std::uint32_t slot = map.find_or_insert(chunk.keys[k], static_cast<std::uint32_t>(voxels.size()), inserted);
      if (inserted) voxels.emplace_back();
      Accumulator& acc = voxels[slot];
      acc.sum += chunk.voxels[k].sum;
      acc.intensity += chunk.voxels[k].intensity;
      acc.count += chunk.voxels[k].count;
    }
  }

  VoxelizedCloud out;
  out.voxel_m = voxel_m;
  out.cloud.origin_m = cloud.origin_m;
  out.cloud.points.resize(voxels.size());
  out.counts.resize(voxels.size());
  if (with_intensity) out.cloud.intensity.resize(voxels.size());
  tbb::parallel_for(std::size_t{0}, voxels.size(), [&](std::size_t v) {
    const double inv = 1.0 / voxels[v].count;
    out.cloud.points[v] = (voxels[v].sum * inv).cast<float>();
    out.counts[v] = voxels[v].count;
    if (with_intensity) out.cloud.intensity[v] = static_cast<float>(voxels[v].intensity * inv);
  });
  return out;
}

}  // namespace k4reg
