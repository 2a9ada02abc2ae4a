#include "k4reg/project/link_judging.h"

#include <fmt/format.h>

#include "k4reg/project/pair_stage.h"
#include "k4reg/project/two_sided_margin.h"
#include "k4reg/util/error.h"
#include "k4reg/util/stage_timing.h"

namespace k4reg {
namespace {

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

// A link's verdict in words: how it was accepted, or why not.
std::string selection_reason(const LinkSelection& s, const LinkCandidates& candidates, bool loop_pose_won,
                             bool screened_out_of_loops) {
  switch (s.verdict) {
    case LinkVerdict::kConfirmed:
      return fmt::format("closes {} of its {} loops{}{}", s.loops_closed, s.loops,
                         s.candidate > 0 ? fmt::format(" with pairwise hypothesis {}, not the winner", s.candidate) : "",
                         loop_pose_won ? ", with a pose its loops implied that its clouds support better than the pairwise winner" : "");
    case LinkVerdict::kConsistent:
      return fmt::format("closes its {} loops, though none alone tells it from a symmetric twin", s.loops);
    case LinkVerdict::kUnchecked:
      return screened_out_of_loops ? "in no loop of the screened pairs, so nothing checks it (pairs all registers every pair)"
                                   : "in no loop; accepted on its pairwise verdict";
    case LinkVerdict::kContradicted:
      return fmt::format("contradicts the loops: none of its {} hypotheses closes any of its {} loops (smallest residual {:.3g} m)",
                         candidates.transforms.size(), s.loops, s.loop_residual_m);
    case LinkVerdict::kUnresolved:
      return s.loops == 0 ? "ambiguous pairwise result in no loop that could resolve it"
                          : fmt::format("ambiguous pairwise result whose {} loops do not all close, and none vouches for it",
                                        s.loops);
    case LinkVerdict::kFailed:
    case LinkVerdict::kInconsistent:
    case LinkVerdict::kPending: break;  // reasons set where they arise
  }
  return {};
}

}  // namespace

void judge_weak_links_from_both_sides(const ProjectInputs& in, const std::vector<ScanPair>& pairs,
                                      std::vector<LinkCandidates>& candidates, ProjectResult& result) {
  const StageTimer timer(result.timings, "both_sides");
  for (std::size_t l = 0; l < result.links.size(); ++l) {
    const LinkCandidates& c = candidates[l];
    if (c.transforms.size() < 2 || !c.well_supported || c.margin >= kAmbiguousMargin) continue;
    check(in.cancel);
    if (in.progress) in.progress("selection", 0.5 * static_cast<double>(l) / result.links.size());  // judging is part of it
    ProjectLink& link = result.links[l];
    RegistrationParams judge = in.pairwise;
    judge.overlap = link.overlap_used;  // at the project's scale, as the loops' poses are judged
    const auto [s, t] = pairs[l];
    const TwoSidedJudgement j = judge_from_both_sides(in.scans[s], in.scans[t], candidates[l], judge, in.extents, in.cancel);
    if (!j.judged) continue;
    link.reverse_judged = true;
    link.runner_up_preferred = j.runner_up_preferred;
    link.reverse_margin = j.reverse_margin;
    link.two_sided_margin = j.margin;
    link.transform = candidates[l].transforms.front();
    link.cloud_score = candidates[l].scores.front();
  }
}

void judge_poses_open_loops_imply(const ProjectInputs& in, const std::vector<ScanPair>& pairs,
                                  std::vector<LinkCandidates>& candidates, ProjectResult& result) {
  std::vector<std::vector<Eigen::Matrix4d>> implied;
  {
    const StageTimer timer(result.timings, "selection");
    const LoopSelectionResult first = select_loop_consistent(candidates, in.extents);
    implied = poses_implied_by_open_loops(candidates, first, in.extents);
  }
  const StageTimer timer(result.timings, "loop_poses");
  for (std::size_t l = 0; l < result.links.size(); ++l) {
    if (implied[l].empty()) continue;
    check(in.cancel);
    if (in.progress) in.progress("selection", 0.5 + 0.5 * static_cast<double>(l) / result.links.size());  // judging is part of it
    const auto [s, t] = pairs[l];
    RegistrationParams judge = in.pairwise;
    // At the project's scale (or the automatic start), not at a finer one the pair may have stepped down to.
    judge.overlap = result.links[l].overlap_used;
    // The winner and the implied poses (the runner-ups already lost to the winner on these clouds).
    std::vector<Eigen::Matrix4d> poses{candidates[l].transforms.front()};
    poses.insert(poses.end(), implied[l].begin(), implied[l].end());
    PairOutcome outcome;
    const auto judge_start = SteadyClock::now();
    try {
      outcome.result = judge_poses(in.scans[s], in.scans[t], judge, poses, in.cancel);
    } catch (const Error& e) {
      if (e.code() == ErrorCode::kCancelled || e.code() == ErrorCode::kDeadlineExceeded) throw;
    }
    outcome.seconds = result.links[l].seconds + seconds_since(judge_start);
    result.links[l].judged_loop_poses = implied[l].size();
    // The pair's own result stands unless an implied pose, refined, beats its winner on its clouds, or comes so
    // close that the clouds cannot tell them apart: then the judged result, flagged ambiguous, replaces it and
    // the loops choose between the two.
    if (!outcome.result) continue;
    const LoopPoseJudgement judgement = judge_implied_poses(candidates[l], implied[l], *outcome.result, in.extents);
    if (judgement == LoopPoseJudgement::kWinnerStands) continue;
    candidates[l] = link_from_outcome(outcome, pairs[l], result.links[l]);
    result.links[l].loop_pose_won = judgement == LoopPoseJudgement::kImpliedWon;
  }
}

void select_links(const std::vector<LinkCandidates>& candidates, const std::vector<ScanPair>& pairs,
                  const std::vector<ScanExtent>& extents, ProjectResult& result) {
  const StageTimer timer(result.timings, "selection");
  const LoopSelectionResult selection = select_loop_consistent(candidates, extents);
  result.loops_checked = selection.loops_checked;
  result.loops_inconsistent = selection.loops_inconsistent;
  for (std::size_t l = 0; l < result.links.size(); ++l) {
    ProjectLink& link = result.links[l];
    const LinkSelection& s = selection.links[l];
    link.loops = s.loops;
    link.loops_closed = s.loops_closed;
    link.loop_residual_m = s.loop_residual_m;
    if (candidates[l].transforms.empty()) continue;  // failed, reason set
    link.verdict = s.verdict;
    link.candidate = s.candidate;
    // With screened pairs a link in no loop may owe that to the screen, not to the scene: where its scans' other
    // partners were not all registered, nothing checked it, so it is not taken on its pairwise verdict alone.
    const bool screened_out_of_loops = result.pairs_used == PairSelection::kScreened &&
                                       s.verdict == LinkVerdict::kUnchecked &&
                                       screen_left_out_a_partner(result.scans.size(), pairs, link.source, link.target);
    link.accepted = s.accepted() && !screened_out_of_loops;
    if (link.accepted) link.transform = candidates[l].transforms[s.candidate];
    if (s.verdict != LinkVerdict::kFailed)
      link.reason = selection_reason(s, candidates[l], link.loop_pose_won, screened_out_of_loops);
    if (link.accepted) {
      result.scans[link.source].links.push_back(l);
      result.scans[link.target].links.push_back(l);
    }
  }
}

}  // namespace k4reg
