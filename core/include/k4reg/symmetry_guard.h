// The symmetry guard (beyond the paper, whose failures were all 180-degree flips of a symmetric room):
// each distinct 4PCS hypothesis is settled by a short coarse ICP and re-scored on the voxelised clouds,
// where the furniture that breaks a room's symmetry is visible: how much of the source the target
// covers, less how much of it lands in space the target scanner saw to be empty (points the target
// scanner could not see are no evidence). 4PCS on a symmetric room often finds only the flipped pose,
// so the best hypothesis's twins under half turns about the target's principal axes compete too.
// Cost: a few ICP iterations and one pass over the coarse source per hypothesis, plus three twins.
#pragma once

#include <vector>

#include "k4reg/cancellation.h"
#include "k4reg/free_space.h"
#include "k4reg/icp.h"
#include "k4reg/point_cloud.h"
#include "k4reg/registration.h"

namespace k4reg {

struct SymmetryGuardResult {
  std::vector<Hypothesis> hypotheses;  // distinct after refinement, best cloud_score first
  double ambiguity_margin = 1.0;       // (best - runner-up) / best; 1 when there is no runner-up
};

// Uses the two coarsest levels of the ICP pyramids and scores on the second. free_space may be null.
SymmetryGuardResult rank_hypotheses(const IcpPyramid& source, const IcpPyramid& target,
                                    std::vector<Hypothesis> hypotheses, const FreeSpaceImage* free_space,
                                    const CancellationToken* cancel = nullptr);

}  // namespace k4reg
