// How firmly the accepted links hold each scan to the reference, beyond what symmetry can copy. In a
// symmetric scene every scan has a twin placement (turned by the symmetry) that closes every loop as well;
// moving a set of scans to their twins changes exactly the links that cross the set's boundary, each of
// which then takes a pairwise runner-up. The cheapest such move costs the minimum cut between the scan
// and the reference, with each link weighted by its pairwise margin (a link confirmed by a vouching loop
// weighs as much as one unambiguous pair; a poorly supported or non-winning one nothing). A scan is held
// when that cut reaches kAmbiguousMargin, the margin a single pair needs: for two scans the rule is the
// pairwise verdict, and evidence from several independent pairs adds up.
// Cost: a max-flow per scan on the link graph, stopped once the flow reaches the cap (a few augmenting
// paths of O(N^2) each for N scans).
#pragma once

#include <cstddef>
#include <vector>

namespace k4reg {

struct WeightedLink {
  std::size_t a = 0, b = 0;  // scan indices
  double weight = 0.0;       // >= 0
};

// Per scan, the minimum cut between it and `reference` over the links, capped at `cap` (the reference
// itself gets `cap`).
std::vector<double> scan_strengths(std::size_t scans, const std::vector<WeightedLink>& links, std::size_t reference,
                                   double cap);

}  // namespace k4reg
