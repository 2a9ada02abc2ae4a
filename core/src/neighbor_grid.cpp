#include "k4reg/neighbor_grid.h"

#include <string>

#include "k4reg/error.h"

namespace k4reg {

NeighborGrid::NeighborGrid(const std::vector<Eigen::Vector3f>& points, double cell_m)
    : points_(&points), cell_m_(cell_m), inv_cell_(static_cast<float>(1.0 / cell_m)), cells_(points.size() / 4 + 16) {
  if (!(cell_m > 0.0)) fail(ErrorCode::kInvalidArgument, "neighbour grid cell must be positive, got " + std::to_string(cell_m));
  std::vector<std::uint32_t> cell_of(points.size());
  std::vector<std::uint32_t> counts;
  for (std::size_t i = 0; i < points.size(); ++i) {
    bool inserted = false;
    const std::uint32_t cell = cells_.find_or_insert(pack_voxel_key(voxel_index(points[i], inv_cell_)),
                                                     static_cast<std::uint32_t>(counts.size()), inserted);
    if (inserted) counts.push_back(0);
    ++counts[cell];
    cell_of[i] = cell;
  }
  offsets_.assign(counts.size() + 1, 0);
  for (std::size_t c = 0; c < counts.size(); ++c) offsets_[c + 1] = offsets_[c] + counts[c];
  order_.resize(points.size());
  std::vector<std::uint32_t> fill(offsets_.begin(), offsets_.end() - 1);
  for (std::size_t i = 0; i < points.size(); ++i) order_[fill[cell_of[i]]++] = static_cast<std::uint32_t>(i);
}

}  // namespace k4reg
