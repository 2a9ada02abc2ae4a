// For a known rotation, the translations that bring the most source points onto target points: every
// (source, target) pair votes for the shift that would make them meet, on a grid of cell_m. Where a
// pose is a symmetric twin of another, the twin's rotation is known (a half-turn composed with it) but
// not where its axis lies: the axis through the target's centre misses a monument seen from both sides
// by metres when the plaza, not the gate, dominates the scan. The vote needs no centre at all.
// Ground that fits anywhere along itself spreads its votes over a plane of shifts; what stands on it
// piles them into one cell. Cost: O(source x target) votes, e.g. 1500 x 1500 in about 10 ms where the box of
// possible shifts fits an array of counts (at most 4 M cells), several times that in a hash map otherwise.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace k4reg {

// Up to `peaks` shifts (target = rotation * source + shift), most votes first, each more than
// `separation_cells` cells (per axis) from the earlier ones. Deterministic: ties go to the smaller cell key.
std::vector<Eigen::Vector3d> vote_translations(const std::vector<Eigen::Vector3f>& source,
                                               const std::vector<Eigen::Vector3f>& target,
                                               const Eigen::Matrix3d& rotation, double cell_m, std::size_t peaks,
                                               int separation_cells = 1);

}  // namespace k4reg
