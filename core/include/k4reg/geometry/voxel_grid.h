// Centroid voxel grid: one point per occupied voxel at the mean position (and mean intensity) of the
// points inside it, plus how many there were. Voxels are hashed, so extents of kilometres at
// centimetre spacing work (PCL's VoxelGrid overflows 32-bit indices there and silently returns its input).
// Cost: O(n) time, parallel over fixed chunks (the output is identical for any thread count).
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "k4reg/util/cancellation.h"
#include "k4reg/geometry/point_cloud.h"

namespace k4reg {

struct VoxelizedCloud {
  PointCloud cloud;                   // centroids (same origin_m as the input); intensity if the input had it
  std::vector<std::uint32_t> counts;  // points per voxel, parallel to cloud.points
  double voxel_m = 0.0;
};

// Throws kInvalidArgument when voxel_m is not positive or the extent needs more than 2^21 voxels per axis.
VoxelizedCloud voxel_grid(const PointCloud& cloud, double voxel_m, const CancellationToken* cancel = nullptr);

// Voxel index of a coordinate (floor(x / voxel)), packed 21 bits per axis; shared with the neighbour grid.
// Inline: the neighbour searches call them for every cell they visit.
constexpr int kVoxelAxisBits = 21;
constexpr int kVoxelAxisLimit = 1 << (kVoxelAxisBits - 1);  // |index| < 2^20 per axis

inline std::uint64_t pack_voxel_key(const Eigen::Vector3i& index) {
  const std::uint64_t mask = (1ULL << kVoxelAxisBits) - 1;
  return (static_cast<std::uint64_t>(index.x() + kVoxelAxisLimit) & mask) |
         ((static_cast<std::uint64_t>(index.y() + kVoxelAxisLimit) & mask) << kVoxelAxisBits) |
         ((static_cast<std::uint64_t>(index.z() + kVoxelAxisLimit) & mask) << (2 * kVoxelAxisBits));
}

inline Eigen::Vector3i voxel_index(const Eigen::Vector3f& p, float inv_voxel) {
  // Saturated before the conversion (an out-of-range float -> int conversion is undefined and wraps in practice):
  // far points get indices beyond kVoxelAxisLimit, which voxel_grid() refuses. NaN saturates too.
  constexpr float kSaturation = 1 << 30;
  auto axis = [inv_voxel](float v) {
    const float f = std::floor(v * inv_voxel);
    return static_cast<int>(f > kSaturation ? kSaturation : f >= -kSaturation ? f : -kSaturation);  // NaN -> low
  };
  return Eigen::Vector3i(axis(p.x()), axis(p.y()), axis(p.z()));
}

}  // namespace k4reg
