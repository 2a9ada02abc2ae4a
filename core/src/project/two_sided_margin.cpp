#include "k4reg/project/two_sided_margin.h"

#include <algorithm>
#include <utility>

#include "k4reg/geometry/rigid_motion.h"
#include "k4reg/util/error.h"

namespace k4reg {
namespace {

// (a - b) / max(a, b); 0 where neither scores.
double side_margin(double a, double b) {
  const double larger = std::max(a, b);
  return larger > 0 ? (a - b) / larger : 0.0;
}

}  // namespace

TwoSidedJudgement judge_from_both_sides(const PreparedScan& source, const PreparedScan& target, LinkCandidates& link,
                                        const RegistrationParams& params, const std::vector<double>& scan_radius_m,
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
  // The refined score from the target's side of the judged pose that stands for `pose` (within the link's loop
  // tolerance, displacement where the target scan is); 0 where none does.
  const double target_radius_m = scan_radius_m.at(link.target);
  auto reverse_score = [&](const Eigen::Matrix4d& pose) {
    for (const Hypothesis& h : judged.hypotheses)
      if (h.refined_score > 0 &&
          displacement_m(rigid_inverse(h.transform) * pose, target_radius_m) <= kLoopToleranceFactor * link.tolerance_m)
        return h.refined_score;
    return 0.0;
  };
  const double forward = side_margin(link.scores[0], link.scores[1]);
  double reverse = side_margin(reverse_score(inverted[0]), reverse_score(inverted[1]));
  double both = forward + reverse;
  out.judged = true;
  if (both < 0) {
    std::swap(link.transforms[0], link.transforms[1]);
    std::swap(link.scores[0], link.scores[1]);
    out.runner_up_preferred = true;
    reverse = -reverse, both = -both;
  }
  out.reverse_margin = reverse;
  out.margin = both;
  link.margin = both;
  link.ambiguous = both < kAmbiguousMargin;
  return out;
}

}  // namespace k4reg
