// The other answer for a scan held too weakly (scan_strength.h): where it goes when the scans on its side of the
// cheapest cut take their twin placements. Each link across the cut then takes another of its candidates; the
// one that loses least to its chosen candidate (the highest share of its score) decides the motion of the whole
// side, which in a symmetric scene is the symmetry itself, whichever link proposes it. A user who knows the site
// can then pick between the two placements instead of registering the scan again.
// Cost: O(links x candidates).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "k4reg/project/loop_closure.h"
#include "k4reg/project/project_registration.h"

namespace k4reg {

// The twin placement of `scan` (whose side of the cut is `moves_with`, sorted, it among them), from the placed
// poses in `project` and the candidates of the links in `used` (indices into project.links and candidates,
// each with its chosen `candidate`). Nothing where no link across the cut has another candidate.
std::optional<Eigen::Matrix4d> twin_placement(const ProjectResult& project, const std::vector<LinkCandidates>& candidates,
                                              const std::vector<std::size_t>& used,
                                              const std::vector<std::size_t>& moves_with, std::size_t scan);

}  // namespace k4reg
