// Where a project's pairs are registered. The default runs them one after the other in this process, each on all
// threads; another runner may send them elsewhere (the service's peers) and run them concurrently. Whatever the
// runner, each pair must get register_clouds' result for its two clouds and the parameters, so that the project's
// poses are the same wherever its pairs ran.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <vector>

#include "k4reg/geometry/point_cloud.h"
#include "k4reg/project/candidate_pairs.h"
#include "k4reg/registration/prepared_scan.h"
#include "k4reg/registration/registration.h"
#include "k4reg/util/cancellation.h"
#include "k4reg/util/error.h"

namespace k4reg {

// One pair's registration: its result, or why it could not be registered (kFailedPrecondition, a degenerate
// cloud, ...); how long it took.
struct PairOutcome {
  std::optional<RegistrationResult> result;
  std::optional<Error> error;
  double seconds = 0.0;
};

class PairRunner {
 public:
  using Done = std::function<void(std::size_t index, PairOutcome outcome)>;
  virtual ~PairRunner() = default;
  // Registers pairs[k] = (source, target) for every k, calling done(k, outcome) as each finishes, one call at a
  // time. Throws k4reg::Error kCancelled / kDeadlineExceeded once `cancel` fires (pairs in flight are dropped).
  // The scans are prepared once for the whole project (prepared_scan.h): a runner that registers here shares
  // their voxels and keypoints between pairs; one that sends pairs elsewhere sends their clouds.
  virtual void run(const std::vector<PreparedScan>& scans, const std::vector<ScanPair>& pairs,
                   const RegistrationParams& params, const CancellationToken* cancel, const Done& done) = 0;
};

// In this process, in order, each pair on params.threads threads.
class LocalPairRunner : public PairRunner {
 public:
  void run(const std::vector<PreparedScan>& scans, const std::vector<ScanPair>& pairs, const RegistrationParams& params,
           const CancellationToken* cancel, const Done& done) override;
};

// One pair in this process, as LocalPairRunner runs it (for a runner that falls back to local work).
PairOutcome register_pair(const PreparedScan& source, const PreparedScan& target, const RegistrationParams& params,
                          const CancellationToken* cancel);

}  // namespace k4reg
