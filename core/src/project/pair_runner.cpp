#include "k4reg/project/pair_runner.h"

#include <chrono>

namespace k4reg {

PairOutcome register_pair(const PreparedScan& source, const PreparedScan& target, const RegistrationParams& params,
                          const CancellationToken* cancel) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  PairOutcome outcome;
  try {
    outcome.result = register_clouds(source, target, params, cancel);
  } catch (const Error& e) {
    if (e.code() == ErrorCode::kCancelled || e.code() == ErrorCode::kDeadlineExceeded) throw;
    outcome.error = e;
  }
  outcome.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return outcome;
}

void LocalPairRunner::run(const std::vector<PreparedScan>& scans, const std::vector<ScanPair>& pairs,
                          const RegistrationParams& params, const CancellationToken* cancel, const Done& done) {
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    check(cancel);
    done(k, register_pair(scans[pairs[k].first], scans[pairs[k].second], params, cancel));
  }
}

}  // namespace k4reg
