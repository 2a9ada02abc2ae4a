// A link judged from both sides (two_sided_margin.h) on the symmetric hall's opposite corners, where the source's
// side cannot tell the truth from the half turn and the target's side can.
#include <gtest/gtest.h>

#include "k4reg/geometry/rigid_motion.h"
#include "k4reg/project/two_sided_margin.h"
#include "k4reg/registration/prepared_scan.h"
#include "sim/scanner.h"
#include "sim/scene.h"

namespace k4reg {
namespace {

// The hall's two stations about their scanners, 20 m across.
const std::vector<ScanExtent> kHallExtents(2, ScanExtent{Eigen::Vector3d::Zero(), 20.0});

// Hall layout 4, stations 0 -> 1: from station 0's side the half turn explains the source as fully as the truth
// (both 1.00), since the partition station 0 saw lands where station 1 could not look; from station 1's side the
// partition it saw contradicts the half turn.
class HallOppositeCorners : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const sim::Scene hall = sim::make_scene("hall", 4);
    sim::ScanParams scan;
    scan.points = 150000;
    scan.seed = 1;
    a_ = new sim::SimulatedScan(sim::simulate_scan(hall, 0, scan));
    scan.seed = 2;
    b_ = new sim::SimulatedScan(sim::simulate_scan(hall, 1, scan));
  }
  static void TearDownTestSuite() {
    delete a_;
    delete b_;
  }
  static Eigen::Matrix4d truth() { return rigid_inverse(b_->scan_to_scene) * a_->scan_to_scene; }
  static inline sim::SimulatedScan *a_ = nullptr, *b_ = nullptr;
};

TEST_F(HallOppositeCorners, TargetsSideTurnsATieIntoTheTruthWhicheverCandidateCameFirst) {
  const PreparedScan source(a_->cloud), target(b_->cloud);
  RegistrationParams params;
  params.min_scale_m = 0.1;
  params.overlap = 0.4;
  params.seed = 1;
  const RegistrationResult pair = register_clouds(source, target, params);
  const std::vector<ScanExtent>& radius = kHallExtents;
  auto error_m = [&](const Eigen::Matrix4d& t) { return displacement_m(rigid_inverse(truth()) * t, radius[0]); };
  const Hypothesis *true_pose = nullptr, *half_turn = nullptr;
  for (const Hypothesis& h : pair.hypotheses) {
    if (h.refined_score <= 0) continue;
    if (!true_pose && error_m(h.transform) < 0.1) true_pose = &h;
    if (!half_turn && error_m(h.transform) > 30.0) half_turn = &h;
  }
  ASSERT_TRUE(true_pose && half_turn);
  // From the source's side the two are within the ambiguity margin of each other.
  ASSERT_LT(std::abs(true_pose->refined_score - half_turn->refined_score), kAmbiguousMargin);
  RegistrationParams judge = params;
  judge.overlap = pair.overlap_used;
  for (const bool truth_first : {false, true}) {
    const Hypothesis& first = truth_first ? *true_pose : *half_turn;
    const Hypothesis& second = truth_first ? *half_turn : *true_pose;
    LinkCandidates link{0, 1, {first.transform, second.transform}, 0.2, true, 0.0, true,
                        {first.refined_score, second.refined_score}};
    const TwoSidedJudgement j = judge_from_both_sides(source, target, link, judge, radius);
    EXPECT_TRUE(j.judged);
    EXPECT_EQ(j.runner_up_preferred, !truth_first);
    EXPECT_LT(error_m(link.transforms[0]), 0.1) << "the truth goes first";
    EXPECT_GT(error_m(link.transforms[1]), 30.0);
    EXPECT_GT(j.reverse_margin, 0.01);
    EXPECT_GT(j.margin, 0.01);
    EXPECT_DOUBLE_EQ(link.margin, j.margin);
  }
}

// A runner-up the target's side does not refine (here one 200 m away, with nothing to match) is no evidence
// for the winner: scored 0, it gave a reverse margin of 1 (a corridor's half turn over a runner-up that was not
// the truth either, so a project placed the scan 180 deg off). The winner is weighed against the best pose refined
// there instead: in this hall, the truth's half turn, which station 1 tells from the truth by a few hundredths.
TEST_F(HallOppositeCorners, ARunnerUpTheTargetsSideDoesNotRefineIsNoEvidence) {
  const PreparedScan source(a_->cloud), target(b_->cloud);
  Eigen::Matrix4d away = truth();
  away(0, 3) += 200.0;
  LinkCandidates link{0, 1, {truth(), away}, 0.2, true, 0.01, true, {0.9, 0.89}};
  RegistrationParams params;
  params.min_scale_m = 0.1;
  params.overlap = 0.4;
  const TwoSidedJudgement j = judge_from_both_sides(source, target, link, params, kHallExtents);
  EXPECT_TRUE(j.judged);
  EXPECT_FALSE(j.runner_up_preferred);
  EXPECT_GT(j.reverse_margin, 0.0);
  EXPECT_LT(j.reverse_margin, 0.2);
  EXPECT_TRUE(link.ambiguous);
  EXPECT_TRUE(link.transforms.front().isApprox(truth()));
}

TEST_F(HallOppositeCorners, ALinkWithOneCandidateIsNotJudged) {
  const PreparedScan source(a_->cloud), target(b_->cloud);
  LinkCandidates link{0, 1, {truth()}, 0.2, false, 1.0, true, {1.0}};
  RegistrationParams params;
  params.min_scale_m = 0.1;
  params.overlap = 0.4;
  EXPECT_FALSE(judge_from_both_sides(source, target, link, params, kHallExtents).judged);
  EXPECT_DOUBLE_EQ(link.margin, 1.0);
}

}  // namespace
}  // namespace k4reg
