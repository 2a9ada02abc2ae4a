// How firmly the accepted links hold each scan against a twin placement that moves a whole set of scans by one
// motion M (in a symmetric hall, one of its half turns): every link across the cut then takes its candidate for M
// and loses its margin over that candidate. scan_strength.h's per-link cut weighs each link by its margin over its
// own best runner-up, a lower bound, since the links' runner-ups may be different motions. So for a scan that bound
// leaves under kAmbiguousMargin, each motion that every link across the cut offers a candidate for is tried as one
// twin (a motion some link never found is not a twin the evidence offers): every link weighs its margin over its
// candidate for that motion; the scan's strength is the cheapest cut over those motions, whose twin placement is
// reported. Where no motion is offered across, the per-link cut stands. Link weights as in scan_strength.h.
// Cost: nothing more where every scan is held by the per-link cut. Per weakly held scan: O(links across x
// candidates) pose comparisons and, per motion all of them offer, one scan_holds.
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
