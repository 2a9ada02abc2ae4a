#include "k4reg/project/project_registration.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <tuple>

#include "k4reg/geometry/rigid_motion.h"
#include "k4reg/geometry/sampling.h"
#include "k4reg/project/loop_closure.h"
#include "k4reg/project/partner_screen.h"
#include "k4reg/project/pose_graph.h"
#include "k4reg/project/scan_conflicts.h"
#include "k4reg/project/twin_motion.h"
#include "k4reg/project/two_sided_margin.h"
#include "k4reg/registration/ambiguity_margin.h"
#include "k4reg/registration/translation_constraint.h"
#include "k4reg/util/error.h"
#include "k4reg/util/median.h"
#include "k4reg/util/stopwatch.h"

namespace k4reg {
namespace {

// Where a scan's points lie, in its file's frame: their centroid and, as the radius a rotation error moves them
// by, the robust diameter (the centroid lies within the 2nd..98th percentile box, so no corner of it is farther;
// stray far returns do not count).
ScanExtent scan_extent(const PointCloud& cloud) {
  return {centroid(cloud.points) + cloud.origin_m, robust_diameter(cloud.points)};
}

// The pose of scan `scan` that a link to an already placed scan proposes.
Eigen::Matrix4d proposed_pose(const ProjectResult& r, const ProjectLink& link, std::size_t scan) {
  return scan == link.source ? r.scans[link.target].pose * link.transform
                             : r.scans[link.source].pose * rigid_inverse(link.transform);
}

// Initial poses by consensus, one scan at a time from the reference: every accepted link from an unplaced
// scan to a placed one proposes a pose, and each proposal counts the proposals that agree with it (within
// the two links' tolerances). A scan is placed only where a strict majority of its links agree; the best
// supported proposal of all goes first (then more loops closed, better support, lower link index). A wrong
// link that slipped through the loops is outvoted here rather than carried along a spanning tree. Scans
// that never gain a majority stay unregistered.
void place_scans(ProjectResult& r, const std::vector<ScanExtent>& extents) {
  for (ProjectScan& scan : r.scans) {
    scan.registered = scan.ambiguous = false;
    scan.pose = Eigen::Matrix4d::Identity();
    scan.reason.clear();
    scan.candidate_poses.clear();
  }
  r.scans[r.reference].registered = true;
  using Key = std::tuple<std::size_t, int, double, std::size_t>;  // votes, loops closed, score, -link
  for (;;) {
    std::optional<std::pair<Key, std::pair<std::size_t, Eigen::Matrix4d>>> best;  // key, (scan, pose)
    for (std::size_t x = 0; x < r.scans.size(); ++x) {
      if (r.scans[x].registered) continue;
      std::vector<std::pair<std::size_t, Eigen::Matrix4d>> proposals;  // link, pose
      for (std::size_t l : r.scans[x].links) {
        const ProjectLink& link = r.links[l];
        if (r.scans[link.source == x ? link.target : link.source].registered)
          proposals.emplace_back(l, proposed_pose(r, link, x));
      }
      for (const auto& [l, pose] : proposals) {
        std::size_t votes = 0;
        for (const auto& [m, other] : proposals)
          votes += displacement_m(rigid_inverse(pose) * other, extents[x]) <=
                   kLoopToleranceFactor * std::hypot(link_tolerance_m(r.links[l]), link_tolerance_m(r.links[m]));
        if (2 * votes <= proposals.size()) continue;
        const Key key{votes, r.links[l].loops_closed, r.links[l].cloud_score, r.links.size() - l};
        if (!best || key > best->first) best = {key, {x, pose}};
      }
    }
    if (!best) break;
    r.scans[best->second.first].pose = best->second.second;
    r.scans[best->second.first].registered = true;
  }
  for (ProjectScan& scan : r.scans)
    if (!scan.registered)
      scan.reason = scan.links.empty() ? "no accepted link connects it to the others (see its links' reasons)"
                                       : "its accepted links do not agree on where it goes, or reach the reference";
}

// Rejects an accepted link: it leaves its scans' lists.
void reject(ProjectResult& r, std::size_t l, const std::string& reason) {
  ProjectLink& link = r.links[l];
  link.accepted = false;
  link.verdict = "inconsistent";
  link.reason = reason;
  for (ProjectScan& scan : r.scans) std::erase(scan.links, l);
}

}  // namespace

double link_tolerance_m(const ProjectLink& link) { return std::max(2.0 * link.min_scale_m_used, link.rmse_m); }

namespace {

// A pair's link as registered (before selection) and its candidates for the loops: the pairwise winner first.
LinkCandidates link_from_outcome(const PairOutcome& outcome, const ScanPair& pair, ProjectLink& link) {
  const auto [s, t] = pair;
  link.source = s;
  link.target = t;
  link.seconds = outcome.seconds;
  LinkCandidates c{s, t, {}, 0.0, false, 0.0, false, {}};
  if (!outcome.result) {
    link.verdict = "failed";
    link.reason = outcome.error ? outcome.error->what() : "not registered";
    return c;
  }
  const RegistrationResult& result = *outcome.result;
  link.rmse_m = result.rmse_m;
  link.overlap = result.overlap;
  link.cloud_score = result.hypotheses.front().refined_score > 0 ? result.hypotheses.front().refined_score
                                                                 : result.hypotheses.front().cloud_score;
  link.ambiguity_margin = result.ambiguity_margin;
  link.ambiguous = result.ambiguous;
  link.well_supported = result.well_supported;
  link.min_scale_m_used = result.min_scale_m_used;
  link.overlap_used = result.overlap_used;
  link.constraint = result.constraint;
  link.reverse_judged = link.runner_up_preferred = false;
  link.reverse_margin = link.two_sided_margin = 0.0;
  c.transforms.push_back(result.transform);
  c.scores.push_back(link.cloud_score);
  // Runner-ups the free space contradicts outright (a score of 0 or less) cannot be the truth.
  for (std::size_t h = 1; h < result.hypotheses.size(); ++h) {
    const Hypothesis& hypothesis = result.hypotheses[h];
    if (hypothesis.cloud_score <= 0) continue;
    c.transforms.push_back(hypothesis.transform);
    c.scores.push_back(hypothesis.refined_score > 0 ? hypothesis.refined_score : hypothesis.cloud_score);
  }
  link.hypotheses = c.transforms.size();
  link.transform = result.transform;
  c.tolerance_m = link_tolerance_m(link);
  c.ambiguous = result.ambiguous;
  c.margin = margin_against_free_space_bar(result.ambiguity_margin, result.free_space_used);
  c.free_space_used = result.free_space_used;
  c.well_supported = result.well_supported;
  return c;
}

// The scans that no loop of the pairs registered so far confirms (a first loop selection, milliseconds).
std::vector<std::size_t> unconfirmed_scans(std::size_t scans, const std::vector<ScanPair>& pairs,
                                           const std::vector<PairOutcome>& outcomes,
                                           const std::vector<ScanExtent>& extents) {
  std::vector<LinkCandidates> found;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    ProjectLink scratch;
    found.push_back(link_from_outcome(outcomes[k], pairs[k], scratch));
  }
  const LoopSelectionResult selection = select_loop_consistent(found, extents);
  std::vector<bool> confirmed(scans, false);
  for (std::size_t k = 0; k < pairs.size(); ++k)
    if (selection.links[k].verdict == LinkVerdict::kConfirmed) confirmed[pairs[k].first] = confirmed[pairs[k].second] = true;
  std::vector<std::size_t> unconfirmed;
  for (std::size_t i = 0; i < scans; ++i)
    if (!confirmed[i]) unconfirmed.push_back(i);
  return unconfirmed;
}

// Whether the screen left out a pair that could have closed a triangle with link (a, b): a pair of a or b
// with a third scan. Where it left none out, a link in no loop owes that to the scene, as with all pairs.
bool screen_left_out_a_partner(std::size_t scans, const std::vector<ScanPair>& pairs, std::size_t a, std::size_t b) {
  std::vector<int> registered(scans, 0);  // pairs of a or b with each scan
  for (const auto& [s, t] : pairs) {
    if (s == a || s == b) ++registered[t];
    if (t == a || t == b) ++registered[s];
  }
  for (std::size_t c = 0; c < scans; ++c)
    if (c != a && c != b && registered[c] < 2) return true;
  return false;
}

}  // namespace

ProjectResult register_project(const std::vector<PointCloud>& scans, const ProjectParams& params,
                               const CancellationToken* cancel, const ProgressCallback& progress,
                               const PairCallback& on_pair, PairRunner* runner) {
  validate(params.pairwise);
  if (scans.size() < 2)
    fail(ErrorCode::kInvalidArgument, fmt::format("a project needs at least 2 scans, got {}", scans.size()));
  if (params.reference >= scans.size())
    fail(ErrorCode::kInvalidArgument,
         fmt::format("reference scan {} is out of range: the project has {} scans (indices start at 0)", params.reference,
                     scans.size()));
  for (std::size_t i = 0; i < scans.size(); ++i)
    if (scans[i].empty()) fail(ErrorCode::kInvalidArgument, fmt::format("scan {} is empty", i));
  if (params.partners == 0) fail(ErrorCode::kInvalidArgument, "partners must be at least 1");

  CancellationToken budget(cancel);
  if (params.pairwise.time_budget_s > 0)
    budget.set_deadline(deadline_in(params.pairwise.time_budget_s));
  RegistrationParams pairwise = params.pairwise;
  pairwise.time_budget_s = 0.0;  // the project's deadline covers every pair
  pairwise.search_other_side = false;  // the project's own rule below, for the pairs of scans no loop confirms

  ProjectResult r;
  r.reference = params.reference;
  r.scans.resize(scans.size());
  for (std::size_t i = 0; i < scans.size(); ++i) r.scans[i].points = scans[i].size();

  // Each scan's voxels, keypoints and pyramids are computed once, in its first pair, and shared by the rest.
  const std::vector<PreparedScan> prepared(scans.begin(), scans.end());

  std::vector<ScanExtent> extents(scans.size());
  for (std::size_t i = 0; i < scans.size(); ++i) extents[i] = scan_extent(scans[i]);

  // 1. Pairwise registration, keeping every distinct hypothesis as a candidate for the loops. Large projects
  //    register each scan's best partners only, by a cheap overlap estimate of every pair.
  r.pairs_used = resolved(params.pairs, scans.size());
  std::vector<ScanPair> pairs;
  std::vector<double> estimates;
  if (r.pairs_used == PairSelection::kScreened) {
    const auto screen_start = SteadyClock::now();
    estimates = estimate_overlaps(prepared, pairwise, &budget, progress);
    pairs = best_partners(scans.size(), estimates, params.partners);
    r.pairs_screened = estimates.size();
    add_timing(r.timings, "screen", seconds_since(screen_start));
  } else {
    pairs = candidate_pairs(scans.size(), r.pairs_used, params.pair_list);
  }
  std::vector<PairOutcome> outcomes;
  std::size_t pairs_done = 0;
  LocalPairRunner local;
  // Registers pairs[first...] (wherever the runner sends them).
  auto register_pairs = [&](std::size_t first) {
    const std::vector<ScanPair> batch(pairs.begin() + static_cast<std::ptrdiff_t>(first), pairs.end());
    outcomes.resize(pairs.size());
    (runner ? *runner : local).run(prepared, batch, pairwise, &budget, [&](std::size_t k, PairOutcome outcome) {
      outcomes.at(first + k) = std::move(outcome);
      ProjectLink link;
      link_from_outcome(outcomes[first + k], pairs[first + k], link);
      if (on_pair) on_pair(link, pairs_done, pairs.size());
      ++pairs_done;
      if (progress) progress("pairs", static_cast<double>(pairs_done) / pairs.size());
    });
  };
  register_pairs(0);
  // A screened scan that no loop of its first pairs confirms gets its next best partners too, once: the loops
  // need them to check its links.
  if (r.pairs_used == PairSelection::kScreened) {
    const std::vector<std::size_t> extend = unconfirmed_scans(scans.size(), pairs, outcomes, extents);
    const std::vector<ScanPair> more = more_partners(scans.size(), estimates, pairs, extend, params.partners);
    if (!more.empty()) {
      const std::size_t first_new = pairs.size();
      pairs.insert(pairs.end(), more.begin(), more.end());
      register_pairs(first_new);
    }
  }
  // 4PCS draws its bases in the source, so a pair's search can miss from one side a pose that the other side's
  // bases find (a statuette view whose keypoints its neighbours do not repeat: 21 mm off from its side, exact
  // from theirs). The pairs of a scan that no loop confirms, where they found no well-supported pose, are
  // searched again from the other side; a well-supported result from there replaces theirs, the link's source
  // and target swapped.
  {
    const std::vector<std::size_t> unconfirmed = unconfirmed_scans(scans.size(), pairs, outcomes, extents);
    auto doubtful = [&](std::size_t i) { return std::binary_search(unconfirmed.begin(), unconfirmed.end(), i); };
    std::vector<std::size_t> again;
    for (std::size_t k = 0; k < pairs.size(); ++k)
      if ((doubtful(pairs[k].first) || doubtful(pairs[k].second)) &&
          !(outcomes[k].result && outcomes[k].result->well_supported))
        again.push_back(k);
    const std::size_t first_new = pairs.size();
    for (std::size_t k : again) pairs.emplace_back(pairs[k].second, pairs[k].first);
    if (!again.empty()) register_pairs(first_new);
    for (std::size_t i = 0; i < again.size(); ++i) {
      PairOutcome& reverse = outcomes[first_new + i];
      PairOutcome& forward = outcomes[again[i]];
      const bool swap = reverse.result && reverse.result->well_supported;
      if (const PairOutcome& dropped = swap ? forward : reverse; dropped.result)  // its work still counts
        for (const StageTiming& t : dropped.result->timings) add_timing(r.timings, t.stage, t.seconds);
      reverse.seconds += forward.seconds;
      forward.seconds = reverse.seconds;
      if (swap) {
        pairs[again[i]] = pairs[first_new + i];
        forward = std::move(reverse);
      }
    }
    pairs.resize(first_new);
    outcomes.resize(first_new);
  }
  // In the pairs' order, wherever and in whatever order they ran.
  std::vector<LinkCandidates> candidates;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    ProjectLink& link = r.links.emplace_back();
    candidates.push_back(link_from_outcome(outcomes[k], pairs[k], link));
    if (outcomes[k].result)
      for (const StageTiming& t : outcomes[k].result->timings) add_timing(r.timings, t.stage, t.seconds);
  }

  if (progress) progress("selection", 0.0);

  // 2a. Weak links judged from both sides: a well-supported winner with a small margin, and its runner-up, are
  //     judged again with the scans swapped, and the two sides' margins add up (two_sided_margin.h).
  auto start = SteadyClock::now();
  for (std::size_t l = 0; l < r.links.size(); ++l) {
    const LinkCandidates& c = candidates[l];
    if (c.transforms.size() < 2 || !c.well_supported || c.margin >= kAmbiguousMargin) continue;
    check(&budget);
    if (progress) progress("selection", 0.5 * static_cast<double>(l) / r.links.size());  // judging is part of it
    ProjectLink& link = r.links[l];
    RegistrationParams judge = pairwise;
    judge.overlap = link.overlap_used;  // at the project's scale, as the loops' poses are judged below
    const auto [s, t] = pairs[l];
    const TwoSidedJudgement j = judge_from_both_sides(prepared[s], prepared[t], candidates[l], judge, extents, &budget);
    if (!j.judged) continue;
    link.reverse_judged = true;
    link.runner_up_preferred = j.runner_up_preferred;
    link.reverse_margin = j.reverse_margin;
    link.two_sided_margin = j.margin;
    link.transform = candidates[l].transforms.front();
    link.cloud_score = candidates[l].scores.front();
  }
  add_timing(r.timings, "both_sides", seconds_since(start));

  // 2. One candidate per link, so that the loops close. Where a loop stays open, the pose its other two links
  //    imply for a link is judged on the link's own clouds (the pair's 4PCS may have missed the truth), and the
  //    loops choose again.
  start = SteadyClock::now();
  const LoopSelectionResult first = select_loop_consistent(candidates, extents);
  const std::vector<std::vector<Eigen::Matrix4d>> implied = poses_implied_by_open_loops(candidates, first, extents);
  add_timing(r.timings, "selection", seconds_since(start));
  start = SteadyClock::now();
  for (std::size_t l = 0; l < r.links.size(); ++l) {
    if (implied[l].empty()) continue;
    check(&budget);
    if (progress) progress("selection", 0.5 + 0.5 * static_cast<double>(l) / r.links.size());  // judging is part of it
    const auto [s, t] = pairs[l];
    RegistrationParams judge = pairwise;
    // At the project's scale (or the automatic start), not at a finer one the pair may have stepped down to.
    judge.overlap = r.links[l].overlap_used;
    // The winner and the implied poses (the runner-ups already lost to the winner on these clouds).
    std::vector<Eigen::Matrix4d> poses{candidates[l].transforms.front()};
    poses.insert(poses.end(), implied[l].begin(), implied[l].end());
    PairOutcome outcome;
    const auto judge_start = SteadyClock::now();
    try {
      outcome.result = judge_poses(prepared[s], prepared[t], judge, poses, &budget);
    } catch (const Error& e) {
      if (e.code() == ErrorCode::kCancelled || e.code() == ErrorCode::kDeadlineExceeded) throw;
    }
    outcome.seconds = r.links[l].seconds + seconds_since(judge_start);
    r.links[l].judged_loop_poses = implied[l].size();
    // The pair's own result stands unless an implied pose, refined, beats its winner on its clouds, or comes so
    // close that the clouds cannot tell them apart: then the judged result, flagged ambiguous, replaces it and
    // the loops choose between the two.
    if (!outcome.result) continue;
    const LoopPoseJudgement judgement = judge_implied_poses(candidates[l], implied[l], *outcome.result, extents);
    if (judgement == LoopPoseJudgement::kWinnerStands) continue;
    candidates[l] = link_from_outcome(outcome, pairs[l], r.links[l]);
    r.links[l].loop_pose_won = judgement == LoopPoseJudgement::kImpliedWon;
  }
  add_timing(r.timings, "loop_poses", seconds_since(start));
  start = SteadyClock::now();
  const LoopSelectionResult selection = select_loop_consistent(candidates, extents);
  r.loops_checked = selection.loops_checked;
  r.loops_inconsistent = selection.loops_inconsistent;
  for (std::size_t l = 0; l < r.links.size(); ++l) {
    ProjectLink& link = r.links[l];
    const LinkSelection& s = selection.links[l];
    link.loops = s.loops;
    link.loops_closed = s.loops_closed;
    link.loop_residual_m = s.loop_residual_m;
    if (candidates[l].transforms.empty()) continue;  // failed, reason set
    link.verdict = to_string(s.verdict);
    link.candidate = s.candidate;
    // With screened pairs a link in no loop may owe that to the screen, not to the scene: where its scans' other
    // partners were not all registered, nothing checked it, so it is not taken on its pairwise verdict alone.
    const bool screened_out_of_loops = r.pairs_used == PairSelection::kScreened && s.verdict == LinkVerdict::kUnchecked &&
                                       screen_left_out_a_partner(scans.size(), pairs, link.source, link.target);
    link.accepted = s.accepted() && !screened_out_of_loops;
    if (link.accepted) link.transform = candidates[l].transforms[s.candidate];
    switch (s.verdict) {
      case LinkVerdict::kConfirmed:
        link.reason = fmt::format("closes {} of its {} loops{}{}", s.loops_closed, s.loops,
                                  s.candidate > 0 ? fmt::format(" with pairwise hypothesis {}, not the winner", s.candidate) : "",
                                  link.loop_pose_won ? ", with a pose its loops implied that its clouds support better than the pairwise winner" : "");
        break;
      case LinkVerdict::kConsistent:
        link.reason = fmt::format("closes its {} loops, though none alone tells it from a symmetric twin", s.loops);
        break;
      case LinkVerdict::kUnchecked:
        link.reason = screened_out_of_loops
                          ? "in no loop of the screened pairs, so nothing checks it (pairs all registers every pair)"
                          : "in no loop; accepted on its pairwise verdict";
        break;
      case LinkVerdict::kContradicted:
        link.reason = fmt::format("contradicts the loops: none of its {} hypotheses closes any of its {} loops (smallest residual {:.3g} m)",
                                  candidates[l].transforms.size(), s.loops, s.loop_residual_m);
        break;
      case LinkVerdict::kUnresolved:
        link.reason = s.loops == 0 ? "ambiguous pairwise result in no loop that could resolve it"
                                   : fmt::format("ambiguous pairwise result whose {} loops do not all close, and none vouches for it",
                                                 s.loops);
        break;
      case LinkVerdict::kFailed: break;
    }
    if (link.accepted) {
      r.scans[link.source].links.push_back(l);
      r.scans[link.target].links.push_back(l);
    }
  }
  if (progress) progress("selection", 1.0);
  add_timing(r.timings, "selection", seconds_since(start));

  // 3. Initial poses by consensus, then all poses together over the accepted links that agree with them. A
  //    link the refined project contradicts by more than its loop tolerance is dropped and all solved again.
  start = SteadyClock::now();
  if (progress) progress("refinement", 0.0);
  for (;;) {
    check(&budget);
    place_scans(r, extents);
    std::vector<std::size_t> used;  // accepted links between registered scans, in agreement with the placement
    std::vector<PoseGraphLink> graph;
    std::vector<double> tolerances;
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
      used.push_back(l);
      graph.push_back({link.source, link.target, link.transform, extents[link.source], 1.0});
      tolerances.push_back(link_tolerance_m(link));
    }
    // Each link weighs by its precision: its refinement's residual, against the median link's. A pose its loops
    // implied fits its pair less closely than a pair's own winner (1.2 mm against 0.4-0.7 mm on the bunny).
    if (!graph.empty()) {
      std::vector<double> rmse;
      for (std::size_t l : used) rmse.push_back(r.links[l].rmse_m);
      const double typical_m = median(std::move(rmse));
      for (std::size_t e = 0; e < graph.size(); ++e) {
        const double own_m = r.links[used[e]].rmse_m;
        if (typical_m > 0.0 && own_m > typical_m) graph[e].weight = (typical_m / own_m) * (typical_m / own_m);
      }
    }
    // Scans that a confident pairwise result contradicts leave the project (scan_conflicts.h).
    refuse_conflicted_scans(r, extents);
    refuse_minority_placements(r);
    // Scans held too weakly to tell from a twin placement leave the project, with their links (twin_motion.h).
    const std::vector<TwinHold> holds = holds_against_twins(r, candidates, used, extents, 1.0);
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
    for (std::size_t e = used.size(); e-- > 0;) {
      const ProjectLink& link = r.links[used[e]];
      if (r.scans[link.source].registered && r.scans[link.target].registered) continue;
      used.erase(used.begin() + e);
      graph.erase(graph.begin() + e);
      tolerances.erase(tolerances.begin() + e);
    }
    std::vector<Eigen::Matrix4d> poses;
    for (const ProjectScan& scan : r.scans) poses.push_back(scan.pose);
    PoseGraphParams solver;
    solver.fixed = r.reference;
    solver.levelled = params.pairwise.levelled;
    if (!tolerances.empty()) solver.huber_m = median(tolerances);
    const PoseGraphResult refined = optimize_pose_graph_robustly(poses, graph, solver);
    // The link the refined project contradicts most, beyond its tolerance, goes; then all again.
    std::size_t worst = used.size();
    double worst_excess = 1.0;
    for (std::size_t e = 0; e < used.size(); ++e) {
      const double excess = refined.residual_m[e] / (kLoopToleranceFactor * tolerances[e]);
      if (excess > worst_excess) worst = e, worst_excess = excess;
    }
    if (worst < used.size()) {
      reject(r, used[worst], fmt::format("disagrees with the refined project by {:.3g} m (tolerance {:.3g} m)",
                                         refined.residual_m[worst], kLoopToleranceFactor * tolerances[worst]));
      continue;
    }
    double sum_sq = 0.0;
    for (std::size_t e = 0; e < used.size(); ++e) {
      r.links[used[e]].residual_m = refined.residual_m[e];
      sum_sq += refined.residual_m[e] * refined.residual_m[e];
    }
    r.global_rmse_m = used.empty() ? 0.0 : std::sqrt(sum_sq / used.size());
    for (std::size_t i = 0; i < r.scans.size(); ++i)
      if (r.scans[i].registered) r.scans[i].pose = refined.poses[i];
    // Each scan's links pin it along the directions their surfaces face, in the project's frame.
    for (std::size_t l : used) {
      const ProjectLink& link = r.links[l];
      const Eigen::Matrix3d in_project =
          rotated_constraint(link.constraint, r.scans[link.target].pose.topLeftCorner<3, 3>());
      r.scans[link.source].constraint += in_project;
      r.scans[link.target].constraint += in_project;
    }
    for (ProjectScan& scan : r.scans) scan.constraint = normalized_constraint(scan.constraint);
    break;
  }
  r.scans_registered = std::count_if(r.scans.begin(), r.scans.end(), [](const ProjectScan& s) { return s.registered; });
  // As the pairs judged them where they ran here; else (pairs run on peers) what is known without a search.
  for (std::size_t i = 0; i < r.scans.size(); ++i) r.scans[i].scanner_position = prepared[i].scanner_known(&budget);
  if (progress) progress("refinement", 1.0);
  add_timing(r.timings, "refinement", seconds_since(start));
  return r;
}

}  // namespace k4reg
