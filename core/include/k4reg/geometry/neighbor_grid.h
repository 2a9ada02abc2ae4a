// Fixed-radius neighbour search on a hashed grid whose cells are about as large as the search radius:
// a query visits the (at most 27) cells its ball touches. Every cell next to an occupied one keeps the list
// of its occupied neighbours, so a query costs one hash look-up instead of up to 27 (ICP, the DoG and
// the 4PCS verifier are dominated by these look-ups). For the near-uniform voxelised clouds of this pipeline this
// is several times faster than a k-d tree. Cost: O(n) to build; O(neighbours) per query.
// A grid queried about once per point (the congruent-set search builds one per 4PCS base) is built without those
// lists (Queries::kFew): they cost 27 hash insertions per occupied cell, and a query then looks up the at most 8
// cells its ball's box touches.
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

#include "k4reg/geometry/hash_map.h"
#include "k4reg/geometry/voxel_grid.h"

namespace k4reg {

class NeighborGrid {
 public:
  enum class Queries { kMany, kFew };
  NeighborGrid(const std::vector<Eigen::Vector3f>& points, double cell_m, Queries queries = Queries::kMany);

  double cell_m() const { return cell_m_; }
  std::size_t bytes() const;  // heap bytes held

  // Calls f(index, squared_distance) for every point within radius_m of q, in the order of the cells' packed
  // keys (z, y, x) and, within a cell, of insertion. For radius_m <= cell_m it visits only the occupied
  // cells around q's that the query ball reaches (on average 21 of the 27); otherwise every cell it touches.
  template <typename F>
  void for_each_within(const Eigen::Vector3f& q, float radius_m, F&& f) const {
    const float r2 = radius_m * radius_m;
    auto visit = [&](std::uint32_t cell) {
      for (std::uint32_t k = offsets_[cell]; k < offsets_[cell + 1]; ++k) {
        const float d2 = (sorted_[k] - q).squaredNorm();
        if (d2 <= r2) f(order_[k], d2);
      }
    };
    if (radius_m <= cell_m_ && !near_offsets_.empty()) {
      // Any point within one cell lies in one of the 27 cells around q's: those listed for q's cell.
      const Around around = cells_around(q);
      for (std::uint32_t n = around.first; n < around.last; ++n)
        if (around.box_distance2(near_codes_[n]) <= r2) visit(near_cells_[n]);
      return;
    }
    const Eigen::Vector3i lo = voxel_index((q.array() - radius_m).matrix(), inv_cell_);
    const Eigen::Vector3i hi = voxel_index((q.array() + radius_m).matrix(), inv_cell_);
    for (int z = lo.z(); z <= hi.z(); ++z)
      for (int y = lo.y(); y <= hi.y(); ++y)
        for (int x = lo.x(); x <= hi.x(); ++x) {
          const std::uint64_t key = pack_voxel_key(Eigen::Vector3i(x, y, z));
          if (!occupied_.may_hold(key)) continue;
          const std::uint32_t cell = cells_.find(key);
          if (cell != VoxelKeyMap::kAbsent) visit(cell);
        }
  }

  // Index of the nearest point within radius_m (<= cell_m) of q, or -1; squared distance in *d2. Visits q's
  // own cell first and then only the neighbouring cells that can still hold a nearer point: in a converged
  // ICP most of the 27 are farther away than the match already found.
  int nearest_within(const Eigen::Vector3f& q, float radius_m, float* d2 = nullptr) const {
    return nearest_within(q, radius_m, d2, [](std::uint32_t, float) { return true; });
  }
  // The same among the points that accept(index, squared_distance) lets count.
  template <typename Accept>
  int nearest_within(const Eigen::Vector3f& q, float radius_m, float* d2, Accept&& accept) const {
    int best = -1;
    float best_d2 = std::numeric_limits<float>::max();
    auto visit = [&](std::uint32_t cell, float bound) {
      for (std::uint32_t k = offsets_[cell]; k < offsets_[cell + 1]; ++k) {
        const float dd = (sorted_[k] - q).squaredNorm();
        if (dd <= bound && dd < best_d2 && accept(order_[k], dd)) best_d2 = dd, best = static_cast<int>(order_[k]);
      }
    };
    const float r2 = radius_m * radius_m;
    if (radius_m > cell_m_ || near_offsets_.empty()) {
      for_each_within(q, radius_m, [&](std::uint32_t i, float dd) {
        if (dd < best_d2 && accept(i, dd)) best_d2 = dd, best = static_cast<int>(i);
      });
    } else {
      const Around around = cells_around(q);
      for (std::uint32_t n = around.first; n < around.last; ++n)
        if (near_codes_[n] == kHomeCode) visit(near_cells_[n], r2);
      for (std::uint32_t n = around.first; n < around.last; ++n) {
        if (near_codes_[n] == kHomeCode) continue;
        const float box = around.box_distance2(near_codes_[n]);
        if (box <= r2 && box < best_d2) visit(near_cells_[n], r2);
      }
    }
    if (d2) *d2 = best_d2;
    return best;
  }

  bool any_within(const Eigen::Vector3f& q, float radius_m) const { return nearest_within(q, radius_m) >= 0; }

 private:
  static constexpr std::uint8_t kHomeCode = 13;  // (0, 0, 0), see near_codes_

  // The occupied cells around q's cell (near_cells_[first, last)) and q's squared gaps to its cell's
  // lower and upper faces per axis, which bound the distance to a neighbouring cell.
  struct Around {
    std::uint32_t first = 0, last = 0;
    float gap2[3][3] = {};  // [axis][dx + 1]
    // Shrunk by 1e-4: a point on a cell face may have been binned to either side in float arithmetic.
    float box_distance2(std::uint8_t code) const {
      return 0.9999f * (gap2[0][code % 3] + gap2[1][code / 3 % 3] + gap2[2][code / 9]);
    }
  };
  Around cells_around(const Eigen::Vector3f& q) const {
    Around a;
    const Eigen::Vector3i index = voxel_index(q, inv_cell_);
    const std::uint32_t home = near_map_.find(pack_voxel_key(index));
    if (home == VoxelKeyMap::kAbsent) return a;
    a.first = near_offsets_[home], a.last = near_offsets_[home + 1];
    const float cell = static_cast<float>(cell_m_);
    for (int axis = 0; axis < 3; ++axis) {
      const float lower = std::max(0.0f, (q(axis) * inv_cell_ - static_cast<float>(index(axis))) * cell);
      const float upper = std::max(0.0f, cell - lower);
      a.gap2[axis][0] = lower * lower, a.gap2[axis][2] = upper * upper;
    }
    return a;
  }

  double cell_m_;
  float inv_cell_;
  VoxelKeyMap cells_;
  KeyBits occupied_;                    // the general search's empty cells (the congruent-set search's) mostly end here
  std::vector<std::uint32_t> offsets_;  // CSR: cell c holds order_[offsets_[c] .. offsets_[c+1])
  std::vector<std::uint32_t> order_;
  std::vector<Eigen::Vector3f> sorted_;  // points[order_[k]]: a cell's points are contiguous in memory
  // Every cell within one cell of an occupied one -> the occupied cells among its 27, in z, y, x order
  // (the order of the general loop below, so both paths make the same calls in the same order). Empty for
  // Queries::kFew.
  VoxelKeyMap near_map_;
  std::vector<std::uint32_t> near_offsets_;  // CSR into near_cells_
  std::vector<std::uint32_t> near_cells_;
  // Per near_cells_ entry: where that cell lies from the listing cell, (dx + 1) + 3 (dy + 1) + 9 (dz + 1).
  std::vector<std::uint8_t> near_codes_;
};

}  // namespace k4reg
