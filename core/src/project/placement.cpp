#include "k4reg/project/placement.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <tuple>

#include "k4reg/geometry/rigid_motion.h"
#include "k4reg/project/pose_graph.h"
#include "k4reg/project/scan_conflicts.h"
#include "k4reg/project/twin_motion.h"
#include "k4reg/registration/translation_constraint.h"
#include "k4reg/util/median.h"
#include "k4reg/util/stage_timing.h"

namespace k4reg {
namespace {

// The pose of scan `scan` that a link to an already placed scan proposes.
Eigen::Matrix4d proposed_pose(const ProjectResult& r, const ProjectLink& link, std::size_t scan) {
  return scan == link.source ? r.scans[link.target].pose * link.transform
                             : r.scans[link.source].pose * rigid_inverse(link.transform);
}

// Where the accepted links to already placed scans put scan x: the proposal most of the others agree with
// (within the two links' tolerances), and of those the one nearest the rest (least sum of squared displacements,
// each in units of that tolerance). A link a few of its tolerances off still agrees with the true ones, but lies
// farther from each of them than they lie from each other. None where no proposal has a strict majority.
struct Consensus {
  std::size_t votes = 0, link = 0;
  Eigen::Matrix4d pose;
};

std::optional<Consensus> consensus(const ProjectResult& r, std::size_t x, const std::vector<ScanExtent>& extents) {
  std::vector<std::pair<std::size_t, Eigen::Matrix4d>> proposals;  // link, pose
  for (std::size_t l : r.scans[x].links) {
    const ProjectLink& link = r.links[l];
    if (r.scans[link.source == x ? link.target : link.source].registered)
      proposals.emplace_back(l, proposed_pose(r, link, x));
  }
  std::optional<Consensus> best;
  double best_spread = 0.0;
  for (const auto& [l, pose] : proposals) {
    std::size_t votes = 0;
    double spread = 0.0;
    for (const auto& [m, other] : proposals) {
      const double apart = displacement_m(rigid_inverse(pose) * other, extents[x]) /
                           std::hypot(link_tolerance_m(r.links[l]), link_tolerance_m(r.links[m]));
      if (apart > kLoopToleranceFactor) continue;
      ++votes;
      spread += apart * apart;
    }
    if (2 * votes <= proposals.size()) continue;
    if (!best || votes > best->votes || (votes == best->votes && spread < best_spread)) {
      best = Consensus{votes, l, pose};
      best_spread = spread;
    }
  }
  return best;
}

// Places unplaced scans one at a time, the best supported consensus of all first (then more loops closed, better
// support, lower link index); placed_by: per scan, the link whose proposal placed it.
void place_the_unplaced(ProjectResult& r, const std::vector<ScanExtent>& extents, std::vector<std::size_t>& placed_by) {
  using Key = std::tuple<std::size_t, int, double, std::size_t>;  // votes, loops closed, score, -link
  for (;;) {
    std::optional<std::pair<Key, std::pair<std::size_t, Consensus>>> best;  // key, (scan, consensus)
    for (std::size_t x = 0; x < r.scans.size(); ++x) {
      if (r.scans[x].registered) continue;
      const std::optional<Consensus> c = consensus(r, x, extents);
      if (!c) continue;
      const Key key{c->votes, r.links[c->link].loops_closed, r.links[c->link].cloud_score, r.links.size() - c->link};
      if (!best || key > best->first) best = {key, {x, *c}};
    }
    if (!best) return;
    const auto& [x, c] = best->second;
    r.scans[x].pose = c.pose;
    r.scans[x].registered = true;
    placed_by[x] = c.link;
  }
}

// Places every placed scan again by the consensus of all its placed neighbours; whether one moved (its consensus
// now rests on another link).
bool place_again(ProjectResult& r, const std::vector<ScanExtent>& extents, std::vector<std::size_t>& placed_by) {
  bool moved = false;
  for (std::size_t x = 0; x < r.scans.size(); ++x) {
    if (!r.scans[x].registered || x == r.reference) continue;
    const std::optional<Consensus> c = consensus(r, x, extents);
    if (!c || c->link == placed_by[x]) continue;
    r.scans[x].pose = c->pose;
    placed_by[x] = c->link;
    moved = true;
  }
  return moved;
}

// Rejects an accepted link: it leaves its scans' lists.
void reject(ProjectResult& r, std::size_t l, const std::string& reason) {
  ProjectLink& link = r.links[l];
  link.accepted = false;
  link.verdict = LinkVerdict::kInconsistent;
  link.reason = reason;
  for (ProjectScan& scan : r.scans) std::erase(scan.links, l);
}

// The accepted links between registered scans that agree with the placement, as pose-graph links, each with
// its tolerance; the rest are rejected.
struct LinkGraph {
  std::vector<std::size_t> used;  // indices into ProjectResult::links
  std::vector<PoseGraphLink> links;
  std::vector<double> tolerances_m;

  void erase(std::size_t e) {
    used.erase(used.begin() + e);
    links.erase(links.begin() + e);
    tolerances_m.erase(tolerances_m.begin() + e);
  }
};

LinkGraph graph_of_agreeing_links(ProjectResult& r, const std::vector<ScanExtent>& extents) {
  LinkGraph graph;
  for (std::size_t l = 0; l < r.links.size(); ++l) {
    const ProjectLink& link = r.links[l];
    if (!link.accepted) continue;
    if (!r.scans[link.source].registered || !r.scans[link.target].registered) continue;
    const double misfit = displacement_m(link_misfit(r.scans[link.source].pose, r.scans[link.target].pose, link.transform),
                                         extents[link.source]);
    const double tolerance = kLoopToleranceFactor * link_tolerance_m(link);
    if (misfit > tolerance) {
      reject(r, l, fmt::format("disagrees with the poses most links support by {:.3g} m (tolerance {:.3g} m)", misfit, tolerance));
      continue;
    }
    graph.used.push_back(l);
    graph.links.push_back({link.source, link.target, link.transform, extents[link.source], 1.0});
    graph.tolerances_m.push_back(link_tolerance_m(link));
  }
  // Each link weighs by its precision: its refinement's residual, against the median link's. A pose its loops
  // implied fits its pair less closely than a pair's own winner (1.2 mm against 0.4-0.7 mm on the bunny).
  if (!graph.links.empty()) {
    std::vector<double> rmse;
    for (std::size_t l : graph.used) rmse.push_back(r.links[l].rmse_m);
    const double typical_m = median(std::move(rmse));
    for (std::size_t e = 0; e < graph.links.size(); ++e) {
      const double own_m = r.links[graph.used[e]].rmse_m;
      if (typical_m > 0.0 && own_m > typical_m) graph.links[e].weight = (typical_m / own_m) * (typical_m / own_m);
    }
  }
  return graph;
}

// Scans held too weakly to tell from a twin placement leave the project (twin_motion.h): not registered, with
// both placements where the twin motion is known.
void refuse_weakly_held_scans(ProjectResult& r, const std::vector<LinkCandidates>& candidates, const LinkGraph& graph,
                              const std::vector<ScanExtent>& extents) {
  const std::vector<TwinHold> holds = holds_against_twins(r, candidates, graph.used, extents, 1.0);
  for (std::size_t i = 0; i < r.scans.size(); ++i) {
    ProjectScan& scan = r.scans[i];
    scan.strength = scan.registered ? holds[i].strength : 0.0;
    if (!scan.registered || holds[i].strength >= kAmbiguousMargin) continue;
    scan.registered = false;
    scan.reason = fmt::format(
        "held too weakly: its links' margins (strength {:.3f} < {}) cannot tell it from a twin placement",
        holds[i].strength, kAmbiguousMargin);
    if (!holds[i].motion) continue;
    scan.ambiguous = true;
    scan.candidate_poses = {scan.pose, *holds[i].motion * scan.pose};
    scan.reason += "; both placements are given, the one its links prefer first";
  }
}

// The link the refined project contradicts most, beyond its tolerance, is rejected; whether there was one.
bool reject_the_worst_misfit(ProjectResult& r, const LinkGraph& graph, const PoseGraphResult& refined) {
  std::size_t worst = graph.used.size();
  double worst_excess = 1.0;
  for (std::size_t e = 0; e < graph.used.size(); ++e) {
    const double excess = refined.residual_m[e] / (kLoopToleranceFactor * graph.tolerances_m[e]);
    if (excess > worst_excess) worst = e, worst_excess = excess;
  }
  if (worst == graph.used.size()) return false;
  reject(r, graph.used[worst], fmt::format("disagrees with the refined project by {:.3g} m (tolerance {:.3g} m)",
                                           refined.residual_m[worst], kLoopToleranceFactor * graph.tolerances_m[worst]));
  return true;
}

// The refined poses, the links' residuals and each scan's constraint: its links pin it along the directions
// their surfaces face, in the project's frame.
void adopt_refinement(ProjectResult& r, const LinkGraph& graph, const PoseGraphResult& refined) {
  double sum_sq = 0.0;
  for (std::size_t e = 0; e < graph.used.size(); ++e) {
    r.links[graph.used[e]].residual_m = refined.residual_m[e];
    sum_sq += refined.residual_m[e] * refined.residual_m[e];
  }
  r.global_rmse_m = graph.used.empty() ? 0.0 : std::sqrt(sum_sq / graph.used.size());
  for (std::size_t i = 0; i < r.scans.size(); ++i)
    if (r.scans[i].registered) r.scans[i].pose = refined.poses[i];
  for (std::size_t l : graph.used) {
    const ProjectLink& link = r.links[l];
    const Eigen::Matrix3d in_project =
        rotated_constraint(link.constraint, r.scans[link.target].pose.topLeftCorner<3, 3>());
    r.scans[link.source].constraint += in_project;
    r.scans[link.target].constraint += in_project;
  }
  for (ProjectScan& scan : r.scans) scan.constraint = normalized_constraint(scan.constraint);
}

}  // namespace

void place_by_consensus(ProjectResult& r, const std::vector<ScanExtent>& extents) {
  for (ProjectScan& scan : r.scans) {
    scan.registered = scan.ambiguous = false;
    scan.pose = Eigen::Matrix4d::Identity();
    scan.reason.clear();
    scan.candidate_poses.clear();
  }
  r.scans[r.reference].registered = true;
  std::vector<std::size_t> placed_by(r.scans.size(), r.links.size());
  // A scan moved may give another its majority, and a scan placed may move another: a few rounds settle a project.
  for (std::size_t round = 0; round < r.scans.size(); ++round) {
    place_the_unplaced(r, extents, placed_by);
    if (!place_again(r, extents, placed_by)) break;
  }
  for (ProjectScan& scan : r.scans)
    if (!scan.registered)
      scan.reason = scan.links.empty() ? "no accepted link connects it to the others (see its links' reasons)"
                                       : "its accepted links do not agree on where it goes, or reach the reference";
}

void place_and_refine(const ProjectInputs& in, const std::vector<LinkCandidates>& candidates, bool levelled,
                      ProjectResult& r) {
  const StageTimer timer(r.timings, "refinement");
  if (in.progress) in.progress("refinement", 0.0);
  for (;;) {
    check(in.cancel);
    place_by_consensus(r, in.extents);
    LinkGraph graph = graph_of_agreeing_links(r, in.extents);
    // Scans that a confident pairwise result contradicts leave the project (scan_conflicts.h).
    refuse_conflicted_scans(r, in.extents);
    refuse_minority_placements(r);
    refuse_weakly_held_scans(r, candidates, graph, in.extents);
    for (std::size_t e = graph.used.size(); e-- > 0;) {
      const ProjectLink& link = r.links[graph.used[e]];
      if (!r.scans[link.source].registered || !r.scans[link.target].registered) graph.erase(e);
    }
    std::vector<Eigen::Matrix4d> poses;
    for (const ProjectScan& scan : r.scans) poses.push_back(scan.pose);
    PoseGraphParams solver;
    solver.fixed = r.reference;
    solver.levelled = levelled;
    if (!graph.tolerances_m.empty()) solver.huber_m = median(graph.tolerances_m);
    const PoseGraphResult refined = optimize_pose_graph_robustly(poses, graph.links, solver);
    if (reject_the_worst_misfit(r, graph, refined)) continue;  // then all again
    adopt_refinement(r, graph, refined);
    break;
  }
  r.scans_registered = std::count_if(r.scans.begin(), r.scans.end(), [](const ProjectScan& s) { return s.registered; });
}

}  // namespace k4reg
