// Where the pairs run does not change the project: a runner that registers them concurrently and out of order
// gives the poses of the local runner, bit for bit; a pair it cannot register is a failed link; cancellation stops it.
#include <gtest/gtest.h>

#include <mutex>
#include <thread>

#include "k4reg/io/cloud_io.h"
#include "k4reg/project/pair_runner.h"
#include "k4reg/project/project_registration.h"

namespace k4reg {
namespace {

const std::string kBunny = std::string(K4REG_TEST_DATA_DIR) + "/bunny/";

// Every pair at once on its own thread, reported last to first.
class ReversedConcurrentRunner : public PairRunner {
 public:
  std::size_t failing = SIZE_MAX;  // this pair reports an error instead of registering
  void run(const std::vector<PreparedScan>& scans, const std::vector<ScanPair>& pairs, const RegistrationParams& params,
           const CancellationToken* cancel, const Done& done) override {
    std::vector<PairOutcome> outcomes(pairs.size());
    std::vector<std::thread> threads;
    for (std::size_t k = 0; k < pairs.size(); ++k)
      threads.emplace_back([&, k] {
        RegistrationParams one = params;
        one.threads = 1;  // the same result on any thread count
        outcomes[k] = register_pair(scans[pairs[k].first], scans[pairs[k].second], one, cancel);
      });
    for (std::thread& t : threads) t.join();
    for (std::size_t k = pairs.size(); k-- > 0;) {
      if (k == failing) outcomes[k] = {std::nullopt, Error(ErrorCode::kFailedPrecondition, "peer gone"), 0.0};
      done(k, std::move(outcomes[k]));
    }
  }
};

class PairRunnerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    for (const char* file : {"bun000.ply", "bun045.ply", "bun315.ply"}) scans.push_back(read_cloud(kBunny + file));
    params.pairwise.min_scale_m = 0.002;
    params.pairwise.overlap = 0.5;
    params.pairwise.seed = 1;
  }
  std::vector<PointCloud> scans;
  ProjectParams params;
};

TEST_F(PairRunnerTest, ConcurrentOutOfOrderPairsGiveTheLocalPosesBitForBit) {
  const ProjectResult local = register_project(scans, params);
  ReversedConcurrentRunner runner;
  std::vector<std::size_t> seen;
  const ProjectResult elsewhere = register_project(
      scans, params, nullptr, {}, [&](const ProjectLink& link, std::size_t, std::size_t) { seen.push_back(link.source); },
      &runner);
  ASSERT_EQ(local.scans.size(), elsewhere.scans.size());
  for (std::size_t i = 0; i < local.scans.size(); ++i) {
    EXPECT_EQ(local.scans[i].registered, elsewhere.scans[i].registered);
    EXPECT_EQ(local.scans[i].pose, elsewhere.scans[i].pose) << "scan " << i;
  }
  for (std::size_t l = 0; l < local.links.size(); ++l) {
    EXPECT_EQ(local.links[l].source, elsewhere.links[l].source);
    EXPECT_EQ(local.links[l].verdict, elsewhere.links[l].verdict);
    EXPECT_EQ(local.links[l].transform, elsewhere.links[l].transform);
  }
  EXPECT_EQ(seen, (std::vector<std::size_t>{1, 0, 0}));  // (1, 2) finished first, then (0, 2), (0, 1)
  EXPECT_EQ(local.scans_registered, 3u);
}

TEST_F(PairRunnerTest, APairTheRunnerCannotRegisterIsAFailedLink) {
  ReversedConcurrentRunner runner;
  runner.failing = 0;
  const ProjectResult result = register_project(scans, params, nullptr, {}, {}, &runner);
  EXPECT_EQ(result.links[0].verdict, LinkVerdict::kFailed);
  EXPECT_NE(result.links[0].reason.find("peer gone"), std::string::npos);
  EXPECT_FALSE(result.links[0].accepted);
  EXPECT_NE(result.links[1].verdict, LinkVerdict::kFailed);
}

TEST_F(PairRunnerTest, CancellationStopsTheLocalRunner) {
  CancellationToken cancel;
  cancel.cancel();
  LocalPairRunner runner;
  const std::vector<PreparedScan> prepared(scans.begin(), scans.end());
  EXPECT_THROW(runner.run(prepared, {{0, 1}}, params.pairwise, &cancel, [](std::size_t, PairOutcome) {}), Error);
}

// The local runner, keeping what each pair gave.
class RecordingRunner : public PairRunner {
 public:
  std::vector<std::pair<ScanPair, RegistrationResult>> results;
  void run(const std::vector<PreparedScan>& scans, const std::vector<ScanPair>& pairs, const RegistrationParams& params,
           const CancellationToken* cancel, const Done& done) override {
    LocalPairRunner().run(scans, pairs, params, cancel, [&](std::size_t k, PairOutcome outcome) {
      if (outcome.result) results.emplace_back(pairs[k], *outcome.result);
      done(k, std::move(outcome));
    });
  }
};

// Scans prepared once for the project (prepared_scan.h; each is in two of the three pairs, as source and as
// target) give each pair what register_clouds gives its two clouds alone.
TEST_F(PairRunnerTest, SharedScanPreparationChangesNoPairByABit) {
  RecordingRunner runner;
  register_project(scans, params, nullptr, {}, {}, &runner);
  ASSERT_EQ(runner.results.size(), 3u);
  for (const auto& [pair, shared] : runner.results) {
    const RegistrationResult alone = register_clouds(scans[pair.first], scans[pair.second], params.pairwise);
    EXPECT_EQ(shared.transform, alone.transform) << pair.first << " -> " << pair.second;
    EXPECT_EQ(shared.rmse_m, alone.rmse_m);
    EXPECT_EQ(shared.ambiguity_margin, alone.ambiguity_margin);
    ASSERT_EQ(shared.hypotheses.size(), alone.hypotheses.size());
    for (std::size_t h = 0; h < alone.hypotheses.size(); ++h)
      EXPECT_EQ(shared.hypotheses[h].transform, alone.hypotheses[h].transform);
  }
}

}  // namespace
}  // namespace k4reg
