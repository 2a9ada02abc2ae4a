#include "k4reg/project/twin_motion.h"

#include <algorithm>
#include <limits>
#include <optional>

#include "k4reg/geometry/rigid_motion.h"
#include "k4reg/registration/ambiguity_margin.h"
#include "k4reg/project/scan_strength.h"

namespace k4reg {
namespace {

bool holds_anything(const ProjectLink& link) { return link.candidate == 0 && link.well_supported; }

// The link's margin from the source's side over its best runner-up: the part a twin motion can raise.
double forward_margin(const ProjectLink& link, const LinkCandidates& c) {
  if (link.reverse_judged && c.scores.size() >= 2) return score_margin(c.scores[0], c.scores[1], c.free_space_used);
  return margin_against_free_space_bar(link.ambiguity_margin, c.free_space_used);
}

// The weight with the source's side's margin given.
double weight_with(const ProjectLink& link, double forward) {
  const double margin = link.reverse_judged ? std::max(forward + link.reverse_margin, 0.0) : forward;
  const double weight = holds_anything(link) ? margin : 0.0;
  return link.verdict == LinkVerdict::kConfirmed ? std::max(weight, kAmbiguousMargin) : weight;
}

// The link's transform once the scans on one side move by `motion`: its source's side, or its target's.
Eigen::Matrix4d moved_link(const ProjectResult& p, const ProjectLink& link, const Eigen::Matrix4d& motion,
                           bool source_moves) {
  const Eigen::Matrix4d to_target = rigid_inverse(p.scans[link.target].pose);
  const Eigen::Matrix4d& source = p.scans[link.source].pose;
  return source_moves ? Eigen::Matrix4d(to_target * motion * source)
                      : Eigen::Matrix4d(to_target * rigid_inverse(motion) * source);
}

// The best score among the link's other candidates that stand for transform t (within its loop tolerance); nothing
// where none does.
std::optional<double> score_standing_for(const LinkCandidates& c, const Eigen::Matrix4d& t, const ScanExtent& extent) {
  std::optional<double> best;
  for (std::size_t k = 1; k < std::min(c.transforms.size(), c.scores.size()); ++k)
    if (displacement_m(rigid_inverse(c.transforms[k]) * t, extent) <= kLoopToleranceFactor * c.tolerance_m)
      best = std::max(best.value_or(c.scores[k]), c.scores[k]);
  return best;
}

// The link's source-side margin over its candidate for `motion` (whichever end moves: the smaller), never less than
// over its best runner-up, which it keeps where it has no candidate for the motion.
double forward_margin_against(const ProjectResult& p, const ProjectLink& link, const LinkCandidates& c,
                              const Eigen::Matrix4d& motion, const std::vector<ScanExtent>& extents) {
  const double fallback = forward_margin(link, c);
  double smallest = std::numeric_limits<double>::infinity();
  for (const bool source_moves : {true, false}) {
    const std::optional<double> score =
        score_standing_for(c, moved_link(p, link, motion, source_moves), extents.at(link.source));
    smallest = std::min(smallest, score ? std::max(score_margin(c.scores[0], *score, c.free_space_used), fallback) : fallback);
  }
  return smallest;
}

}  // namespace

double link_weight(const ProjectLink& link, const LinkCandidates& candidates) {
  return weight_with(link, forward_margin(link, candidates));
}

std::vector<TwinHold> holds_against_twins(const ProjectResult& project, const std::vector<LinkCandidates>& candidates,
                                          const std::vector<std::size_t>& used, const std::vector<ScanExtent>& extents,
                                          double cap) {
  const std::size_t n = project.scans.size();
  auto weighted = [&](auto weight_of) {
    std::vector<WeightedLink> out;
    for (std::size_t l : used) out.push_back({project.links[l].source, project.links[l].target, weight_of(l)});
    return out;
  };
  const std::vector<ScanHold> bound = scan_holds(
      n, weighted([&](std::size_t l) { return link_weight(project.links[l], candidates[l]); }), project.reference, cap);
  std::vector<TwinHold> holds(n);
  for (std::size_t i = 0; i < n; ++i) holds[i].strength = bound[i].strength, holds[i].moves_with = bound[i].moves_with;

  auto against = [&](const Eigen::Matrix4d& motion) {
    return scan_holds(n, weighted([&](std::size_t l) {
                        const ProjectLink& link = project.links[l];
                        return weight_with(link,
                                           forward_margin_against(project, link, candidates[l], motion, extents));
                      }),
                      project.reference, cap);
  };
  for (std::size_t i = 0; i < n; ++i) {
    if (bound[i].strength >= kAmbiguousMargin) continue;
    // The twins its side of the per-link cut could take as one: the motions that every link across the cut (that
    // holds anything) offers a candidate for, read off the first such link's candidates with its moving end moved.
    const std::vector<std::size_t>& side = bound[i].moves_with;
    auto moves = [&](std::size_t scan) { return std::binary_search(side.begin(), side.end(), scan); };
    std::vector<std::size_t> across;
    for (std::size_t l : used)
      if (moves(project.links[l].source) != moves(project.links[l].target) && holds_anything(project.links[l]))
        across.push_back(l);
    if (across.empty()) continue;
    const ProjectLink& first = project.links[across.front()];
    const Eigen::Matrix4d& source = project.scans[first.source].pose;
    const Eigen::Matrix4d& target = project.scans[first.target].pose;
    const LinkCandidates& offered = candidates[across.front()];
    for (std::size_t k = 1; k < offered.transforms.size(); ++k) {
      // p_project = P_target * T * p_source: the motion of the moving end to where candidate k puts it.
      const Eigen::Matrix4d motion =
          moves(first.source) ? Eigen::Matrix4d(target * offered.transforms[k] * rigid_inverse(source))
                              : Eigen::Matrix4d(source * rigid_inverse(offered.transforms[k]) * rigid_inverse(target));
      const bool offered_by_all = std::all_of(across.begin(), across.end(), [&](std::size_t l) {
        const ProjectLink& link = project.links[l];
        return score_standing_for(candidates[l], moved_link(project, link, motion, moves(link.source)),
                                  extents.at(link.source))
            .has_value();
      });
      if (!offered_by_all) continue;
      const ScanHold hold = against(motion)[i];
      if (!holds[i].motion || hold.strength < holds[i].strength) holds[i] = {hold.strength, hold.moves_with, motion};
    }
  }
  return holds;
}

}  // namespace k4reg
