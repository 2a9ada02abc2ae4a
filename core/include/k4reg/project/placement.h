// A project's last stage: its scans placed by the accepted links (link_judging.h) and refined together.
//   initial poses by consensus of the accepted links, from the reference out  ->  conflicts, minority placements
//   (scan_conflicts.h) and each scan's strength against twin placements (scan_strength.h, twin_motion.h)  ->  global
//   refinement (pose_graph.h), where the link that disagrees most with the refined project is dropped and all is
//   solved again.
// A scan that no majority of accepted links places, or that they hold too weakly to tell from a symmetric twin, is
// reported as not registered, never forced into place. Cost: milliseconds (a sparse solve per round).
#pragma once

#include <vector>

#include "k4reg/project/loop_closure.h"
#include "k4reg/project/project_types.h"

namespace k4reg {

// Sets every scan's pose, registered, reason, strength, candidate poses and constraint, the accepted links'
// residuals (rejecting those the placement or the refined project contradicts) and result.global_rmse_m and
// scans_registered. levelled: the refinement turns scans about z only.
void place_and_refine(const ProjectInputs& in, const std::vector<LinkCandidates>& candidates, bool levelled,
                      ProjectResult& result);

}  // namespace k4reg
