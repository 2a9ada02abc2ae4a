#include "k4reg/registration/translation_vote.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "k4reg/geometry/hash_map.h"
#include "k4reg/geometry/voxel_grid.h"

namespace k4reg {

namespace {

// Votes per cell of shift space. Where the box of possible shifts has few enough cells, a flat array
// counts them: 2 M votes then take a few milliseconds instead of tens with a hash look-up each.
class VoteCounts {
 public:
  static constexpr std::size_t kMaxDenseCells = std::size_t{1} << 22;  // 16 MB of counts

  VoteCounts(const Eigen::Vector3i& low, const Eigen::Vector3i& high) : low_(low), size_(high - low + Eigen::Vector3i::Ones()) {
    const double cells = double(size_.x()) * size_.y() * size_.z();
    if (cells <= kMaxDenseCells) dense_.assign(static_cast<std::size_t>(cells), 0);
  }
  bool dense() const { return !dense_.empty(); }

  void add(const Eigen::Vector3i& index) {
    if (dense()) {
      ++dense_[offset(index)];
      return;
    }
    bool inserted = false;
    const std::uint32_t slot = sparse_.find_or_insert(pack_voxel_key(index), static_cast<std::uint32_t>(votes_.size()), inserted);
    if (inserted) {
      votes_.push_back(0);
      indices_.push_back(index);
    }
    ++votes_[slot];
  }

  std::uint32_t at(const Eigen::Vector3i& index) const {
    if (!dense()) {
      const std::uint32_t slot = sparse_.find(pack_voxel_key(index));
      return slot == VoxelKeyMap::kAbsent ? 0 : votes_[slot];
    }
    if ((index.array() < low_.array()).any() || (index.array() >= (low_ + size_).array()).any()) return 0;
    return dense_[offset(index)];
  }

  // The cells with votes and their counts (the same set either way).
  void cells(std::vector<Eigen::Vector3i>& indices, std::vector<std::uint32_t>& votes) const {
    if (!dense()) {
      indices = indices_;
      votes = votes_;
      return;
    }
    for (std::size_t i = 0; i < dense_.size(); ++i)
      if (dense_[i] > 0) {
        const auto x = static_cast<int>(i % size_.x()), y = static_cast<int>(i / size_.x() % size_.y()),
                   z = static_cast<int>(i / size_.x() / size_.y());
        indices.push_back(low_ + Eigen::Vector3i(x, y, z));
        votes.push_back(dense_[i]);
      }
  }

 private:
  std::size_t offset(const Eigen::Vector3i& index) const {
    const Eigen::Vector3i d = index - low_;
    return (static_cast<std::size_t>(d.z()) * size_.y() + d.y()) * size_.x() + d.x();
  }

  Eigen::Vector3i low_, size_;
  std::vector<std::uint32_t> dense_;
  VoxelKeyMap sparse_;
  std::vector<std::uint32_t> votes_;
  std::vector<Eigen::Vector3i> indices_;
};

// floor() without a call into libm (the build targets baseline x86-64, which has no rounding instruction): the
// same cells, several times faster over millions of votes.
int floor_to_int(float x) {
  const int i = static_cast<int>(x);
  return i - (x < static_cast<float>(i));
}

Eigen::Vector3i cell_of(const Eigen::Vector3f& shift, float inverse_cell) {
  const Eigen::Vector3f scaled = shift * inverse_cell;
  return {floor_to_int(scaled.x()), floor_to_int(scaled.y()), floor_to_int(scaled.z())};
}

}  // namespace

std::vector<Eigen::Vector3d> vote_translations(const std::vector<Eigen::Vector3f>& source,
                                               const std::vector<Eigen::Vector3f>& target,
                                               const Eigen::Matrix3d& rotation, double cell_m, std::size_t peaks,
                                               int separation_cells) {
  if (source.empty() || target.empty()) return {};
  const Eigen::Matrix3f r = rotation.cast<float>();
  const float inverse_cell = static_cast<float>(1.0 / cell_m);
  std::vector<Eigen::Vector3f> rotated(source.size());
  Eigen::Vector3f rotated_low = Eigen::Vector3f::Constant(INFINITY), rotated_high = -rotated_low;
  Eigen::Vector3f target_low = rotated_low, target_high = rotated_high;
  for (std::size_t i = 0; i < source.size(); ++i) {
    rotated[i] = r * source[i];
    rotated_low = rotated_low.cwiseMin(rotated[i]);
    rotated_high = rotated_high.cwiseMax(rotated[i]);
  }
  for (const Eigen::Vector3f& q : target) {
    target_low = target_low.cwiseMin(q);
    target_high = target_high.cwiseMax(q);
  }
  // Every vote q - r p lies in this box (float subtraction and flooring keep the order).
  VoteCounts counts(cell_of(target_low - rotated_high, inverse_cell), cell_of(target_high - rotated_low, inverse_cell));
  for (const Eigen::Vector3f& p : rotated)
    for (const Eigen::Vector3f& q : target) counts.add(cell_of(q - p, inverse_cell));
  std::vector<std::uint32_t> votes;
  std::vector<Eigen::Vector3i> indices;
  counts.cells(indices, votes);
  // A true shift's votes straddle cell borders: each cell counts its 3 x 3 x 3 block.
  auto block = [&](const Eigen::Vector3i& index) {
    std::uint64_t sum = 0;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) sum += counts.at(index + Eigen::Vector3i(dx, dy, dz));
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
                    [&](const Eigen::Vector3i& t) { return (t - head).cwiseAbs().maxCoeff() <= separation_cells; }))
      continue;
    taken.push_back(head);
    shifts.push_back((head.cast<double>() + Eigen::Vector3d::Constant(0.5)) * cell_m);
  }
  return shifts;
}

}  // namespace k4reg
