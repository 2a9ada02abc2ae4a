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

// Initial poses by consensus, one scan at a time from the reference: every accepted link from an unplaced scan to
// a placed one proposes a pose; a scan is placed only where a strict majority of its links agree (within the two
// links' tolerances), at the proposal nearest the others that agree, and the best supported consensus of all goes
// first (then more loops closed, better support, lower link index). A wrong link that slipped through the loops is
// outvoted here rather than carried along a spanning tree. Then every scan is placed again by the consensus of all
// its placed neighbours (a scan placed early, on its one link to the reference, is not left where that link alone
// put it), the scans still unplaced are tried again, and so on until nothing moves. Sets each scan's pose and
// registered, and a reason for those that never gain a majority. Cost: O(links per scan ^ 2) per scan and round.
void place_by_consensus(ProjectResult& result, const std::vector<ScanExtent>& extents);

// Sets every scan's pose, registered, reason, strength, candidate poses and constraint, the accepted links'
// residuals (rejecting those the placement or the refined project contradicts) and result.global_rmse_m and
// scans_registered. levelled: the refinement turns scans about z only.
void place_and_refine(const ProjectInputs& in, const std::vector<LinkCandidates>& candidates, bool levelled,
                      ProjectResult& result);

}  // namespace k4reg
