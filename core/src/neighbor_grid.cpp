#include "k4reg/neighbor_grid.h"

#include <algorithm>
#include <string>

#include "k4reg/error.h"

namespace k4reg {

NeighborGrid::NeighborGrid(const std::vector<Eigen::Vector3f>& points, double cell_m)
    : cell_m_(cell_m), inv_cell_(static_cast<float>(1.0 / cell_m)), cells_(points.size() / 4 + 16) {
  if (!(cell_m > 0.0)) fail(ErrorCode::kInvalidArgument, "neighbour grid cell must be positive, got " + std::to_string(cell_m));
  std::vector<std::uint32_t> cell_of(points.size());
  std::vector<std::uint32_t> counts;
  std::vector<Eigen::Vector3i> index_of;  // per occupied cell
  for (std::size_t i = 0; i < points.size(); ++i) {
    bool inserted = false;
    const Eigen::Vector3i index = voxel_index(points[i], inv_cell_);
    const std::uint32_t cell =
        cells_.find_or_insert(pack_voxel_key(index), static_cast<std::uint32_t>(counts.size()), inserted);
    if (inserted) {
      counts.push_back(0);
      index_of.push_back(index);
    }
    ++counts[cell];
    cell_of[i] = cell;
  }
  offsets_.assign(counts.size() + 1, 0);
  for (std::size_t c = 0; c < counts.size(); ++c) offsets_[c + 1] = offsets_[c] + counts[c];
  order_.resize(points.size());
  std::vector<std::uint32_t> fill(offsets_.begin(), offsets_.end() - 1);
  for (std::size_t i = 0; i < points.size(); ++i) order_[fill[cell_of[i]]++] = static_cast<std::uint32_t>(i);
  sorted_.resize(points.size());
  for (std::size_t k = 0; k < points.size(); ++k) sorted_[k] = points[order_[k]];

  // Cells next to occupied ones, then each one's occupied neighbours (counted, filled, sorted by key).
  auto adjacent_keys = [&](std::uint32_t c, auto&& f) {
    for (int z = -1; z <= 1; ++z)
      for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x) f(pack_voxel_key(index_of[c] + Eigen::Vector3i(x, y, z)));
  };
  std::vector<std::uint32_t> near_counts;
  for (std::uint32_t c = 0; c < counts.size(); ++c)
    adjacent_keys(c, [&](std::uint64_t key) {
      bool inserted = false;
      const std::uint32_t near =
          near_map_.find_or_insert(key, static_cast<std::uint32_t>(near_counts.size()), inserted);
      if (inserted) near_counts.push_back(0);
      ++near_counts[near];
    });
  near_offsets_.assign(near_counts.size() + 1, 0);
  for (std::size_t n = 0; n < near_counts.size(); ++n) near_offsets_[n + 1] = near_offsets_[n] + near_counts[n];
  near_cells_.resize(near_offsets_.back());
  std::vector<std::uint32_t> next(near_offsets_.begin(), near_offsets_.end() - 1);
  for (std::uint32_t c = 0; c < counts.size(); ++c)
    adjacent_keys(c, [&](std::uint64_t key) { near_cells_[next[near_map_.find(key)]++] = c; });
  // Packed keys order cells by z, then y, then x.
  for (std::size_t n = 0; n < near_counts.size(); ++n)
    std::sort(near_cells_.begin() + near_offsets_[n], near_cells_.begin() + near_offsets_[n + 1],
              [&](std::uint32_t a, std::uint32_t b) {
                return pack_voxel_key(index_of[a]) < pack_voxel_key(index_of[b]);
              });
}

}  // namespace k4reg
