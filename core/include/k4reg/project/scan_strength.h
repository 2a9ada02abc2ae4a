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

struct ScanHold {
  double strength = 0.0;  // the minimum cut between the scan and the reference, capped
  // Where the cut is under the cap: the scans on the scan's side of a minimum cut (it among them, ascending),
  // the set whose move to its twin placements costs `strength`. Empty where the cut reaches the cap.
  std::vector<std::size_t> moves_with;
};

// Per scan, how it is held to `reference` over the links (the reference itself: `cap`, moving with nothing).
std::vector<ScanHold> scan_holds(std::size_t scans, const std::vector<WeightedLink>& links, std::size_t reference,
                                 double cap);

}  // namespace k4reg
