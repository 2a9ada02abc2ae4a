// A weak link judged from both of its scans' sides. A pair's margin weighs the source's points against what the
// target scanner saw; the symmetry breakers only the target saw (the far side of a partition in a symmetric hall)
// count only with the scans swapped. In such a hall each side holds part of the evidence: margins of 0.02-0.04,
// now on one side, now on the other, and where one side sees none of it the truth and its half turn tie there
// (both explain all of the source). So where a link's pairwise winner is well supported but its margin is under
// kAmbiguousMargin, the target's points judge the winner and the runner-up as well, and the two sides' margins
// add up, as the margins of independent pairs do in a scan's strength (scan_strength.h). Where the two sides
// together prefer the runner-up, it becomes the link's first candidate. The loops and the scans' strength then
// work on the two-sided margin.
// Cost: one judge_poses per link judged (the guard and the verdict of a registration, without keypoints or 4PCS).
#pragma once

#include <vector>

#include "k4reg/project/loop_closure.h"
#include "k4reg/registration/prepared_scan.h"
#include "k4reg/registration/registration.h"
#include "k4reg/util/cancellation.h"

namespace k4reg {

struct TwoSidedJudgement {
  bool judged = false;  // false: not judged (fewer than two candidates, a candidate not refined there, or a failure)
  bool runner_up_preferred = false;  // the two sides together preferred the pairwise runner-up
  double reverse_margin = 0.0;       // from the target's side, the (new) first candidate over its best rival (signed)
  double margin = 0.0;               // both sides' margins added, the first candidate over the second (>= 0)
};

// Judges candidates 0 and 1 of `link` (the pairwise winner and runner-up, with their scores) from the target's
// side: the scans swapped, the two poses inverted, judge_poses at params' scale and overlap. The source's margin
// is (first - second) / the larger of their scores; the target's, the winner's refined score there against the
// best refined pose there that stands for anything else (the runner-up, or a twin the guard added). Where the
// winner or every rival is not refined there, the link is not judged.
// Reorders the two where their sum is negative and sets link.margin and link.ambiguous to the two-sided verdict.
// Rethrows cancellation; another failure leaves the link as it was (judged = false).
TwoSidedJudgement judge_from_both_sides(const PreparedScan& source, const PreparedScan& target, LinkCandidates& link,
                                        const RegistrationParams& params, const std::vector<ScanExtent>& extents,
                                        const CancellationToken* cancel = nullptr);

}  // namespace k4reg
