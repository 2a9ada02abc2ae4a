// A project's links judged against each other, after its pairs (pair_stage.h) and before its placement
// (placement.h):
//   links whose well-supported winner has a small margin judged from both sides (two_sided_margin.h)
//   ->  loop-consistent selection of one candidate per link (loop_closure.h)  ->  where a loop stays open, the
//   poses its other links imply judged on the link's own clouds (judge_poses)  ->  the selection again, which
//   sets each link's verdict, chosen candidate and reason.
// Cost: judging a link costs a guard and a verdict (0.1-1 s at 1 M points; 2-4 s from both sides at 0.7 M
// points), only for weak links and links in open loops; each selection takes milliseconds.
#pragma once

#include <vector>

#include "k4reg/project/loop_closure.h"
#include "k4reg/project/project_types.h"

namespace k4reg {

// A well-supported winner with a small margin, and its runner-up, judged again with the scans swapped: the two
// sides' margins add up (two_sided_margin.h). Updates the link's candidates and result.links' figures.
void judge_weak_links_from_both_sides(const ProjectInputs& in, const std::vector<ScanPair>& pairs,
                                      std::vector<LinkCandidates>& candidates, ProjectResult& result);

// Where a loop stays open, the poses its other two links imply for a link, judged on the link's own clouds (the
// pair's 4PCS may have missed the truth): a pose that wins, or ties with the winner, replaces the link's
// candidates (loop_closure.h, judge_implied_poses).
void judge_poses_open_loops_imply(const ProjectInputs& in, const std::vector<ScanPair>& pairs,
                                  std::vector<LinkCandidates>& candidates, ProjectResult& result);

// The loops choose one candidate per link: each link's verdict, candidate, loops and reason, whether it is
// accepted, and the accepted links of each scan. With screened pairs, a link in no loop whose scans' other
// partners the screen left out is not accepted on its pairwise verdict alone.
void select_links(const std::vector<LinkCandidates>& candidates, const std::vector<ScanPair>& pairs,
                  const std::vector<ScanExtent>& extents, ProjectResult& result);

}  // namespace k4reg
