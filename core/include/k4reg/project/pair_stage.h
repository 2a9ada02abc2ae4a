// A project's first stage: its pairs registered, each keeping its distinct hypotheses as candidates for the loops.
//   the candidate pairs (candidate_pairs.h; for large projects each scan's best partners, partner_screen.h)
//   ->  pairwise K-4PCS per pair, wherever the PairRunner sends it  ->  screened: the next best partners of scans
//   no loop confirms  ->  the pairs of scans no loop confirms that found no well-supported pose, searched again
//   with the scans swapped (4PCS draws its bases in the source)
// Cost: one pairwise registration per pair (0.2-3 s each at 1 M points on 2 cores) and one more per pair searched
// from the other side (none where every scan closes a loop); for screened pairs, one 4PCS round on keypoints per
// pair of scans (about 0.1 s at 1 M points); each check of the loops takes milliseconds.
#pragma once

#include <vector>

#include "k4reg/project/candidate_pairs.h"
#include "k4reg/project/loop_closure.h"
#include "k4reg/project/pair_runner.h"
#include "k4reg/project/project_types.h"

namespace k4reg {

// The pairs registered, in the order the links are reported, and each one's outcome.
struct RegisteredPairs {
  std::vector<ScanPair> pairs;
  std::vector<PairOutcome> outcomes;
};

// Registers the project's pairs. Sets result.pairs_used and pairs_screened and adds the screen's time and that of
// results dropped for the other side's; on_pair hears of each pair as it finishes. runner null = in this process.
RegisteredPairs register_pairs(const ProjectInputs& in, const ProjectParams& params, const PairCallback& on_pair,
                               PairRunner* runner, ProjectResult& result);

// Each pair as a link of result.links (in the pairs' order, wherever and in whatever order they ran) and its
// candidates for the loops; the pairs' stage times are added to result.timings.
std::vector<LinkCandidates> links_of_pairs(const RegisteredPairs& registered, ProjectResult& result);

// A pair's link as registered (before selection) and its candidates for the loops: the pairwise winner first,
// then the runner-ups the free space does not contradict outright.
LinkCandidates link_from_outcome(const PairOutcome& outcome, const ScanPair& pair, ProjectLink& link);

}  // namespace k4reg
