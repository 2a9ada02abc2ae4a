#include "k4reg/project/twin_placement.h"

#include <algorithm>
#include <utility>

#include "k4reg/geometry/rigid_motion.h"

namespace k4reg {

std::optional<Eigen::Matrix4d> twin_placement(const ProjectResult& project, const std::vector<LinkCandidates>& candidates,
                                              const std::vector<std::size_t>& used,
                                              const std::vector<std::size_t>& moves_with, std::size_t scan) {
  auto moves = [&](std::size_t i) { return std::binary_search(moves_with.begin(), moves_with.end(), i); };
  std::optional<std::pair<double, Eigen::Matrix4d>> best;  // the candidate's share of the chosen score, the motion
  for (std::size_t l : used) {
    const ProjectLink& link = project.links.at(l);
    if (moves(link.source) == moves(link.target) || link.candidate < 0) continue;
    const LinkCandidates& c = candidates.at(l);
    const auto chosen = static_cast<std::size_t>(link.candidate);
    if (chosen >= c.scores.size() || c.scores[chosen] <= 0) continue;
    for (std::size_t k = 0; k < std::min(c.transforms.size(), c.scores.size()); ++k) {
      if (k == chosen) continue;
      const double share = c.scores[k] / c.scores[chosen];
      if (best && share <= best->first) continue;
      // p_project = P_target * T * p_source: where candidate k puts the moving end, and the motion that takes it there.
      const bool source_moves = moves(link.source);
      const std::size_t moving = source_moves ? link.source : link.target;
      const Eigen::Matrix4d placed = source_moves ? project.scans[link.target].pose * c.transforms[k]
                                                  : project.scans[link.source].pose * rigid_inverse(c.transforms[k]);
      best = {share, placed * rigid_inverse(project.scans[moving].pose)};
    }
  }
  if (!best) return std::nullopt;
  return best->second * project.scans.at(scan).pose;
}

}  // namespace k4reg
