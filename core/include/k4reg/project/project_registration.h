// Project registration: N scans into one frame (after Theiler, Wegner, Schindler 2015), in three stages:
//   pairs (pair_stage.h): each candidate pair registered by K-4PCS, its distinct hypotheses kept
//   ->  links (link_judging.h): weak links judged from both sides, one candidate per link chosen so that the
//       loops close, the poses open loops imply judged on the links' own clouds
//   ->  placement (placement.h): poses by consensus of the accepted links, scans held too weakly refused, the rest
//       refined together.
// A scan that no majority of accepted links places, or that they hold too weakly to tell it from a symmetric twin,
// is reported as not registered, never forced into place. Pairs run one after the other, each on all threads (or
// wherever a PairRunner sends them), so the result is the same at any thread count and on any runner.
// Cost: the pairs' (seconds each at 1 M points), then the judging of weak links and open loops (a fraction of a
// pair's each); selection and placement take milliseconds.
#pragma once

#include <vector>

#include "k4reg/geometry/point_cloud.h"
#include "k4reg/project/pair_runner.h"
#include "k4reg/project/project_types.h"
#include "k4reg/util/cancellation.h"

namespace k4reg {

// Throws kInvalidArgument for fewer than 2 scans, an empty scan, a reference out of range, partners 0 or bad
// pairwise parameters; kCancelled / kDeadlineExceeded when stopped (time_budget_s of the pairwise parameters bounds
// the whole project). A pair that cannot be registered is a failed link, not an error.
// `runner` registers the pairs (pair_runner.h); null = one after the other in this process. The poses do not
// depend on it.
ProjectResult register_project(const std::vector<PointCloud>& scans, const ProjectParams& params,
                               const CancellationToken* cancel = nullptr, const ProgressCallback& progress = {},
                               const PairCallback& on_pair = {}, PairRunner* runner = nullptr);

}  // namespace k4reg
