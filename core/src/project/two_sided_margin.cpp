#include "k4reg/project/two_sided_margin.h"

#include <algorithm>
#include <optional>
#include <utility>

#include "k4reg/geometry/rigid_motion.h"
#include "k4reg/registration/ambiguity_margin.h"
#include "k4reg/util/error.h"

namespace k4reg {

TwoSidedJudgement judge_from_both_sides(const PreparedScan& source, const PreparedScan& target, LinkCandidates& link,
                                        const RegistrationParams& params, const std::vector<ScanExtent>& extents,
                                        const CancellationToken* cancel) {
  TwoSidedJudgement out;
  if (link.transforms.size() < 2 || link.scores.size() < 2) return out;
  const std::vector<Eigen::Matrix4d> inverted{rigid_inverse(link.transforms[0]), rigid_inverse(link.transforms[1])};
  RegistrationResult judged;
  try {
    judged = judge_poses(target, source, params, inverted, cancel);
  } catch (const Error& e) {
    if (e.code() == ErrorCode::kCancelled || e.code() == ErrorCode::kDeadlineExceeded) throw;
    return out;
  }
  // From the target's side: the refined score of the pose that stands for the winner (within the link's loop
  // tolerance, displacement where the target scan is), against the best refined pose that stands for anything
  // else, the runner-up or a pose the guard added there (its symmetric twins). A pose not refined there (its
  // refinement slid elsewhere, or it was not among the poses refined) says nothing: scored 0, it gave a corridor's
  // half turn a reverse margin of 1 over a runner-up that was not the truth either. So the sides are compared only
  // where the winner and a rival are both refined there.
  const ScanExtent& target_extent = extents.at(link.target);
  auto stands_for = [&](const Hypothesis& h, const Eigen::Matrix4d& pose) {
    return displacement_m(rigid_inverse(h.transform) * pose, target_extent) <= kLoopToleranceFactor * link.tolerance_m;
  };
  std::optional<double> winner, rival;
  bool rival_is_runner_up = false;
  for (const Hypothesis& h : judged.hypotheses) {
    if (h.refined_score <= 0) continue;
    if (stands_for(h, inverted[0])) {
      if (!winner) winner = h.refined_score;
    } else if (!rival || h.refined_score > *rival) {
      rival = h.refined_score;
      rival_is_runner_up = stands_for(h, inverted[1]);
    }
  }
  if (!winner || !rival) return out;
  const double forward = score_margin(link.scores[0], link.scores[1], link.free_space_used);
  double reverse = score_margin(*winner, *rival, judged.free_space_used);
  double both = forward + reverse;
  out.judged = true;
  if (both < 0 && rival_is_runner_up) {
    std::swap(link.transforms[0], link.transforms[1]);
    std::swap(link.scores[0], link.scores[1]);
    out.runner_up_preferred = true;
    reverse = -reverse, both = -both;
  }
  both = std::max(both, 0.0);  // a rival that is not among the link's candidates: the link stays ambiguous
  out.reverse_margin = reverse;
  out.margin = both;
  link.margin = both;
  link.ambiguous = both < kAmbiguousMargin;
  return out;
}

}  // namespace k4reg
