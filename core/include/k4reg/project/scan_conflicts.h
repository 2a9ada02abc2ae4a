// Scans whose placement confident pairwise results contradict. A link whose pairwise verdict was unambiguous
// and well supported, that the loops did not accept, and that puts its two placed scans further apart than its
// tolerance (kLoopToleranceFactor x link_tolerance_m) speaks against both placements: the evidence is in
// conflict. A front/back-symmetric object seen from the back can outvote the truth with such links, consistent
// among themselves; a scan is therefore refused where such links are at least as many as the accepted links that
// place it. Where its accepted links outnumber them (an object's view held by five neighbours, contradicted by
// one flipped pair whose symmetric details neither view saw), the one link is outvoted and the scan stays.
// Cost: O(links).
#pragma once

#include <vector>

#include "k4reg/geometry/rigid_motion.h"
#include "k4reg/project/project_types.h"

namespace k4reg {

// Clears `registered` and sets `reason` on every such scan but the reference. extents: per scan, where
// its points lie (misfits are measured there, as in the loops).
void refuse_conflicted_scans(ProjectResult& result, const std::vector<ScanExtent>& extents);

// Scans placed on a minority of their own evidence: where most of a registered scan's accepted links lead to
// scans the project refused, the few that placed it may be the wrong side of a conflict the others would have
// shown (a symmetric object's back views, placed flipped by their flipped links to the front while their
// true links go to refused neighbours). Refused until none is left (each refusal may leave another in the
// minority); the reference stays. Cost: O(scans x links) per round.
void refuse_minority_placements(ProjectResult& result);

}  // namespace k4reg
