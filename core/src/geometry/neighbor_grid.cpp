#include "k4reg/geometry/neighbor_grid.h"

#include <algorithm>
#include <string>

#include "k4reg/util/error.h"
#include "k4reg/util/held_bytes.h"

namespace k4reg {

NeighborGrid::NeighborGrid(const std::vector<Eigen::Vector3f>& points, double cell_m, Queries queries)
    : cell_m_(cell_m), inv_cell_(static_cast<float>(1.0 / cell_m)), cells_(points.size() / 4 + 16), occupied_(0) {
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
  occupied_ = KeyBits(counts.size());
  for (const Eigen::Vector3i& index : index_of) occupied_.add(pack_voxel_key(index));
  offsets_.assign(counts.size() + 1, 0);
  for (std::size_t c = 0; c < counts.size(); ++c) offsets_[c + 1] = offsets_[c] + counts[c];
  order_.resize(points.size());
  std::vector<std::uint32_t> fill(offsets_.begin(), offsets_.end() - 1);
  for (std::size_t i = 0; i < points.size(); ++i) order_[fill[cell_of[i]]++] = static_cast<std::uint32_t>(i);
  sorted_.resize(points.size());
  for (std::size_t k = 0; k < points.size(); ++k) sorted_[k] = points[order_[k]];
  if (queries == Queries::kFew) return;

  // Cells next to occupied ones, then each one's occupied neighbours (counted, filled, sorted by key).
  // f(key, code) for the 27 cells around occupied cell c; code = (x + 1) + 3 (y + 1) + 9 (z + 1).
  auto adjacent_keys = [&](std::uint32_t c, auto&& f) {
    for (int z = -1; z <= 1; ++z)
      for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x)
          f(pack_voxel_key(index_of[c] + Eigen::Vector3i(x, y, z)), (x + 1) + 3 * (y + 1) + 9 * (z + 1));
  };
  std::vector<std::uint32_t> near_counts;
  for (std::uint32_t c = 0; c < counts.size(); ++c)
    adjacent_keys(c, [&](std::uint64_t key, int) {
      bool inserted = false;
      const std::uint32_t near =
          near_map_.find_or_insert(key, static_cast<std::uint32_t>(near_counts.size()), inserted);
      if (inserted) near_counts.push_back(0);
      ++near_counts[near];
    });
  near_offsets_.assign(near_counts.size() + 1, 0);
  for (std::size_t n = 0; n < near_counts.size(); ++n) near_offsets_[n + 1] = near_offsets_[n] + near_counts[n];
  // Each entry as (code << 32 | cell); cell c lies at minus the offset it was reached by from the listing cell.
  std::vector<std::uint64_t> entries(near_offsets_.back());
  std::vector<std::uint32_t> next(near_offsets_.begin(), near_offsets_.end() - 1);
  for (std::uint32_t c = 0; c < counts.size(); ++c)
    adjacent_keys(c, [&](std::uint64_t key, int code) {
      entries[next[near_map_.find(key)]++] = (static_cast<std::uint64_t>(26 - code) << 32) | c;
    });
  // Ascending codes are the z, y, x order of packed keys (the general loop's order).
  for (std::size_t n = 0; n < near_counts.size(); ++n)
    std::sort(entries.begin() + near_offsets_[n], entries.begin() + near_offsets_[n + 1]);
  near_cells_.resize(entries.size());
  near_codes_.resize(entries.size());
  for (std::size_t k = 0; k < entries.size(); ++k) {
    near_cells_[k] = static_cast<std::uint32_t>(entries[k]);
    near_codes_[k] = static_cast<std::uint8_t>(entries[k] >> 32);
  }
}

std::size_t NeighborGrid::bytes() const {
  return cells_.bytes() + occupied_.bytes() + held_bytes(offsets_) + held_bytes(order_) + held_bytes(sorted_) +
         near_map_.bytes() + held_bytes(near_offsets_) + held_bytes(near_cells_) + held_bytes(near_codes_);
}

}  // namespace k4reg
