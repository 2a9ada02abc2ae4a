#include "k4reg/registration/translation_vote.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "k4reg/geometry/hash_map.h"
#include "k4reg/geometry/voxel_grid.h"

namespace k4reg {

std::vector<Eigen::Vector3d> vote_translations(const std::vector<Eigen::Vector3f>& source,
                                               const std::vector<Eigen::Vector3f>& target,
                                               const Eigen::Matrix3d& rotation, double cell_m, std::size_t peaks) {
  const Eigen::Matrix3f r = rotation.cast<float>();
  const float inverse_cell = static_cast<float>(1.0 / cell_m);
  VoxelKeyMap cells(source.size() * 4);
  std::vector<std::uint32_t> votes;
  std::vector<Eigen::Vector3i> indices;
  for (const Eigen::Vector3f& p : source) {
    const Eigen::Vector3f rotated = r * p;
    for (const Eigen::Vector3f& q : target) {
      const Eigen::Vector3i index = ((q - rotated) * inverse_cell).array().floor().cast<int>();
      bool inserted = false;
      const std::uint32_t slot = cells.find_or_insert(pack_voxel_key(index), static_cast<std::uint32_t>(votes.size()), inserted);
      if (inserted) {
        votes.push_back(0);
        indices.push_back(index);
      }
      ++votes[slot];
    }
  }
  // A true shift's votes straddle cell borders: each cell counts its 3 x 3 x 3 block.
  auto block = [&](const Eigen::Vector3i& index) {
    std::uint64_t sum = 0;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const std::uint32_t slot = cells.find(pack_voxel_key(index + Eigen::Vector3i(dx, dy, dz)));
          if (slot != VoxelKeyMap::kAbsent) sum += votes[slot];
        }
    return sum;
  };
  // Only cells with many votes of their own can head a block worth trying.
  std::vector<std::uint32_t> order(votes.size());
  for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  const std::size_t candidates = std::min<std::size_t>(order.size(), 64 * std::max<std::size_t>(peaks, 1));
  auto by_votes = [&](std::uint32_t a, std::uint32_t b) {
    return votes[a] != votes[b] ? votes[a] > votes[b] : pack_voxel_key(indices[a]) < pack_voxel_key(indices[b]);
  };
  std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(candidates), order.end(), by_votes);
  std::vector<std::pair<std::uint64_t, std::uint32_t>> ranked;  // block votes, cell
  for (std::size_t i = 0; i < candidates; ++i) ranked.emplace_back(block(indices[order[i]]), order[i]);
  std::stable_sort(ranked.begin(), ranked.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<Eigen::Vector3d> shifts;
  std::vector<Eigen::Vector3i> taken;
  for (const auto& entry : ranked) {
    if (shifts.size() == peaks) break;
    const Eigen::Vector3i& head = indices[entry.second];
    if (std::any_of(taken.begin(), taken.end(),
                    [&](const Eigen::Vector3i& t) { return (t - head).cwiseAbs().maxCoeff() <= 1; }))
      continue;
    taken.push_back(head);
    shifts.push_back((head.cast<double>() + Eigen::Vector3d::Constant(0.5)) * cell_m);
  }
  return shifts;
}

}  // namespace k4reg
