#include "k4reg/symmetry_guard.h"

#include <algorithm>
#include <cmath>

#include "k4reg/four_pcs.h"
#include "k4reg/icp.h"
#include "k4reg/neighbor_grid.h"
#include "k4reg/rigid_fit.h"

namespace k4reg {
namespace {

double cloud_score(const std::vector<Eigen::Vector3f>& source, const NeighborGrid& grid, float tau,
                   const Eigen::Matrix4d& t, const FreeSpaceImage* free_space) {
  const Eigen::Affine3f a = to_affine3f(t);
  std::size_t hits = 0, contradicted = 0;
  for (const Eigen::Vector3f& p : source) {
    const Eigen::Vector3f q = a * p;
    if (grid.any_within(q, tau))
      ++hits;
    else if (free_space && free_space->contradicts(q))
      ++contradicted;
  }
  return (static_cast<double>(hits) - static_cast<double>(contradicted)) / std::max<std::size_t>(1, source.size());
}

}  // namespace

SymmetryGuardResult rank_hypotheses(const IcpPyramid& source, const IcpPyramid& target,
                                    std::vector<Hypothesis> hypotheses, const FreeSpaceImage* free_space,
                                    const CancellationToken* cancel) {
  constexpr int kStages = 2, kIterations = 6;  // settle, don't polish: the final ICP does that
  const auto& scored = source.stages.at(kStages - 1);
  const auto& reference = target.stages.at(kStages - 1);
  const double voxel_m = reference.voxel_m;
  const float tau = static_cast<float>(1.5 * voxel_m);
  const NeighborGrid grid(reference.points, 2.0 * tau);  // 8-cell look-ups for the score
  IcpParams quick;
  quick.stages = kStages;
  quick.max_iterations = kIterations;
  for (Hypothesis& h : hypotheses) {
    h.transform = refine_icp(source, target, h.transform, quick, cancel).transform;
    h.cloud_score = cloud_score(scored.points, grid, tau, h.transform, free_space);
  }
  std::stable_sort(hypotheses.begin(), hypotheses.end(),
                   [](const Hypothesis& a, const Hypothesis& b) { return a.cloud_score > b.cloud_score; });
  SymmetryGuardResult result;
  // Hypotheses that ICP brought to the same pose are one hypothesis.
  for (const Hypothesis& h : hypotheses)
    if (std::all_of(result.hypotheses.begin(), result.hypotheses.end(), [&](const Hypothesis& d) {
          return distinct_transforms(d.transform, h.transform, 2.0, 2.0 * voxel_m);
        }))
      result.hypotheses.push_back(h);
  const auto& ranked = result.hypotheses;
  if (ranked.size() >= 2 && ranked[0].cloud_score > 0)
    result.ambiguity_margin = std::clamp((ranked[0].cloud_score - ranked[1].cloud_score) / ranked[0].cloud_score, 0.0, 1.0);
  return result;
}

}  // namespace k4reg
