// How firmly the accepted links hold each scan against a twin placement, where the twin is one motion of a whole
// set of scans. Moving the scans on one side of a cut to their twins moves them all by the same motion M (in a
// symmetric hall, one of its half turns), so every link across the cut then takes its candidate for M and loses
// its margin over that candidate, not over whichever runner-up it scored best. The per-link cut of scan_strength.h
// weighs each link by its margin over its own best runner-up: a lower bound, since the links' best runner-ups may
// be different motions (hall layout 3: station 0's three links each lose least to another of the hall's three half
// turns). So for a scan that bound leaves under kAmbiguousMargin, the twins its side could take as one are tried:
// the motions that every link across the cut offers a candidate for (a motion some link never found is not a twin
// the evidence offers, as the per-link rule knows no runner-up its pair did not find either). Against each, every
// link weighs its margin over its candidate for that motion, or over its best runner-up where it has none; the
// scan's strength is the cheapest cut over those motions, and the cheapest motion gives its twin placement. Where
// no motion is offered across, the per-link cut stands.
// A link's weight, as in scan_strength.h: its margin (two-sided where judged from both sides, with the reverse
// side's margin as judged, against its best rival there) where its first candidate was chosen and is well
// supported; at least one pair's worth where a vouching loop confirmed it; else nothing.
// Cost: nothing more where every scan is held by the per-link cut. Per weakly held scan, per candidate of one link
// across its cut: O(links across x candidates) pose comparisons and, for a motion all of them offer, one
// scan_holds.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "k4reg/project/loop_closure.h"
#include "k4reg/project/project_types.h"

namespace k4reg {

struct TwinHold {
  double strength = 0.0;  // the cheapest cut between the scan and the reference, capped
  // Where under the cap: the scans that move with it in that cut (it among them, ascending), and the motion (in the
  // project's frame) that takes them to their twins; no motion where no link offers another candidate.
  std::vector<std::size_t> moves_with;
  std::optional<Eigen::Matrix4d> motion;
};

// The weight of a link in the scans' strength against its best runner-up (above).
double link_weight(const ProjectLink& link, const LinkCandidates& candidates);

// Per scan, from the placed poses in `project` (reference: project.reference) and the links in `used` (indices into
// project.links and candidates, each with its chosen `candidate`). extents: per scan, as in the loops.
std::vector<TwinHold> holds_against_twins(const ProjectResult& project, const std::vector<LinkCandidates>& candidates,
                                          const std::vector<std::size_t>& used, const std::vector<ScanExtent>& extents,
                                          double cap);

}  // namespace k4reg
