// Fixed-radius neighbour search on a hashed grid whose cells are about as large as the search radius:
// a query visits the (at most 27) cells its ball touches. Every cell next to an occupied one keeps the list
// of its occupied neighbours, so a query costs one hash look-up instead of up to 27 (ICP, the DoG and
// the 4PCS verifier are dominated by these look-ups). For the near-uniform voxelised clouds of this pipeline this
// is several times faster than a k-d tree. Cost: O(n) to build; O(neighbours) per query.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "k4reg/hash_map.h"
#include "k4reg/voxel_grid.h"

namespace k4reg {

class NeighborGrid {
 public:
  NeighborGrid(const std::vector<Eigen::Vector3f>& points, double cell_m);

  double cell_m() const { return cell_m_; }

  // Calls f(index, squared_distance) for every point within radius_m (<= cell_m) of q. Visits only the
  // cells the query ball touches: 8 when radius_m <= cell_m / 2, at most 27 otherwise.
  template <typename F>
  void for_each_within(const Eigen::Vector3f& q, float radius_m, F&& f) const {
    const float r2 = radius_m * radius_m;
    auto visit = [&](std::uint32_t cell) {
      for (std::uint32_t k = offsets_[cell]; k < offsets_[cell + 1]; ++k) {
        const float d2 = (sorted_[k] - q).squaredNorm();
        if (d2 <= r2) f(order_[k], d2);
      }
    };
    if (radius_m <= cell_m_) {
      // Any point within one cell lies in one of the 27 cells around q's: those listed for q's cell.
      const std::uint32_t home = near_map_.find(pack_voxel_key(voxel_index(q, inv_cell_)));
      if (home == VoxelKeyMap::kAbsent) return;
      for (std::uint32_t n = near_offsets_[home]; n < near_offsets_[home + 1]; ++n) visit(near_cells_[n]);
      return;
    }
    const Eigen::Vector3i lo = voxel_index((q.array() - radius_m).matrix(), inv_cell_);
    const Eigen::Vector3i hi = voxel_index((q.array() + radius_m).matrix(), inv_cell_);
    for (int z = lo.z(); z <= hi.z(); ++z)
      for (int y = lo.y(); y <= hi.y(); ++y)
        for (int x = lo.x(); x <= hi.x(); ++x) {
          const std::uint32_t cell = cells_.find(pack_voxel_key(Eigen::Vector3i(x, y, z)));
          if (cell != VoxelKeyMap::kAbsent) visit(cell);
        }
  }

  // Index of the nearest point within radius_m (<= cell_m) of q, or -1; squared distance in *d2.
  int nearest_within(const Eigen::Vector3f& q, float radius_m, float* d2 = nullptr) const {
    int best = -1;
    float best_d2 = std::numeric_limits<float>::max();
    for_each_within(q, radius_m, [&](std::uint32_t i, float dd) {
      if (dd < best_d2) best_d2 = dd, best = static_cast<int>(i);
    });
    if (d2) *d2 = best_d2;
    return best;
  }

  bool any_within(const Eigen::Vector3f& q, float radius_m) const { return nearest_within(q, radius_m) >= 0; }

 private:
  double cell_m_;
  float inv_cell_;
  VoxelKeyMap cells_;
  std::vector<std::uint32_t> offsets_;  // CSR: cell c holds order_[offsets_[c] .. offsets_[c+1])
  std::vector<std::uint32_t> order_;
  std::vector<Eigen::Vector3f> sorted_;  // points[order_[k]]: a cell's points are contiguous in memory
  // Every cell within one cell of an occupied one -> the occupied cells among its 27, in z, y, x order
  // (the order of the general loop below, so both paths make the same calls in the same order).
  VoxelKeyMap near_map_;
  std::vector<std::uint32_t> near_offsets_;  // CSR into near_cells_
  std::vector<std::uint32_t> near_cells_;
};

}  // namespace k4reg
