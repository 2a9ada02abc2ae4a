// Project registration end to end on real range scans (the Stanford bunny, each scan moved by its own
// random rigid motion), and the ways a project can be malformed.
#include <gtest/gtest.h>

#include <map>
#include <random>

#include "k4reg/geometry/rigid_motion.h"
#include "k4reg/io/cloud_io.h"
#include "k4reg/io/gt_pairs.h"
#include "k4reg/project/pair_runner.h"
#include "k4reg/project/project_registration.h"
#include "k4reg/registration/translation_constraint.h"
#include "k4reg/util/error.h"
#include "pose_error.h"

namespace k4reg {
namespace {

const std::string kBunny = std::string(K4REG_TEST_DATA_DIR) + "/bunny/";

// A random rigid motion: any rotation, a shift of up to max_shift_m per axis.
Eigen::Matrix4d random_motion(std::mt19937& rng, double max_shift_m) {
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = rotation_exp(Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized() * 3.0 * std::abs(u(rng)) * 2);
  m.topRightCorner<3, 1>() = 2.0 * max_shift_m * Eigen::Vector3d(u(rng), u(rng), u(rng));
  return m;
}

PointCloud moved(const PointCloud& cloud, const Eigen::Matrix4d& m) {
  std::vector<Eigen::Vector3d> points;
  for (const Eigen::Vector3f& p : cloud.points)
    points.push_back(m.topLeftCorner<3, 3>() * (p.cast<double>() + cloud.origin_m) + m.topRightCorner<3, 1>());
  return make_local_cloud(points, cloud.intensity);
}

// Six bunny scans with a ground-truth transform into bun000's frame, each moved at random (shifts of up to
// max_shift_m per axis).
struct BunnyProject {
  std::vector<std::string> files{"bun000.ply", "bun045.ply", "bun090.ply", "bun270.ply", "bun315.ply", "chin.ply"};
  std::vector<PointCloud> scans;
  std::vector<Eigen::Matrix4d> truth;  // p_project (the moved bun000's frame) = truth * p_scan
  explicit BunnyProject(double max_shift_m = 0.5) {
    std::map<std::string, Eigen::Matrix4d> to_bun000{{"bun000.ply", Eigen::Matrix4d::Identity()}};
    for (const GtPair& p : read_gt_pairs(kBunny + "gt_pairs.log"))
      if (p.target == "bun000.ply") to_bun000[p.source] = p.T_target_source;
    std::mt19937 rng(11);
    std::vector<Eigen::Matrix4d> motion;
    for (const std::string& f : files) {
      motion.push_back(random_motion(rng, max_shift_m));
      scans.push_back(moved(read_cloud(kBunny + f), motion.back()));
    }
    for (std::size_t i = 0; i < files.size(); ++i)
      truth.push_back(motion[0] * to_bun000.at(files[i]) * rigid_inverse(motion[i]));
  }
};

ProjectParams statue_params() {
  ProjectParams p;
  p.pairwise.min_scale_m = 0.002;
  p.pairwise.overlap = 0.5;
  p.pairwise.seed = 1;
  return p;
}

TEST(ProjectRegistration, BunnyScansAllRegisteredWithinAMillimetre) {
  const BunnyProject bunny;
  std::size_t pairs_reported = 0;
  const ProjectResult r = register_project(bunny.scans, statue_params(), nullptr, {},
                                           [&](const ProjectLink&, std::size_t, std::size_t total) {
                                             ++pairs_reported;
                                             EXPECT_EQ(total, 15u);
                                           });
  EXPECT_EQ(pairs_reported, 15u);
  ASSERT_EQ(r.scans.size(), 6u);
  EXPECT_EQ(r.scans_registered, 6u);
  EXPECT_TRUE(r.scans[0].pose.isApprox(Eigen::Matrix4d::Identity()));
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_TRUE(r.scans[i].registered) << bunny.files[i] << ": " << r.scans[i].reason;
    EXPECT_LT(rms_error_m(bunny.scans[i], r.scans[i].pose, bunny.truth[i]), 0.001) << bunny.files[i];
    // A curved object pins every direction: its constraint (trace 3) has no free direction.
    EXPECT_NEAR(r.scans[i].constraint.trace(), 3.0, 1e-9) << bunny.files[i];
    EXPECT_GT(weakest_constraint(r.scans[i].constraint), 0.2) << bunny.files[i];
  }
  EXPECT_EQ(r.pairs_used, PairSelection::kAll);  // the default, auto, at 6 scans
  EXPECT_EQ(r.pairs_screened, 0u);
  EXPECT_EQ(r.links.size(), 15u);
  EXPECT_EQ(r.loops_checked, 20u);
  EXPECT_GT(r.global_rmse_m, 0.0);
  EXPECT_LT(r.global_rmse_m, 0.002);
  for (const ProjectLink& l : r.links) {
    if (l.accepted) {
      EXPECT_GE(l.residual_m, 0.0);
      EXPECT_NEAR(l.constraint.trace(), 3.0, 1e-9);
    }
    // Only a well-supported winner with a small margin is judged from both sides, and its margin then adds up.
    if (l.reverse_judged) {
      EXPECT_TRUE(l.well_supported);
      EXPECT_LT(l.ambiguity_margin, kAmbiguousMargin);
      EXPECT_GE(l.two_sided_margin, 0.0);
    }
  }
  // Pairwise stages, then the project's own.
  auto stage = [&](const std::string& name) {
    return std::any_of(r.timings.begin(), r.timings.end(), [&](const StageTiming& t) { return t.stage == name; });
  };
  EXPECT_TRUE(stage("keypoints") && stage("selection") && stage("refinement"));
}

// Files that put a 0.2 m statuette tens of metres from their origins (exported in site coordinates): the loops and the
// pose graph measure misfits where each scan is, so a twentieth of a degree does not count as centimetres about an
// origin 30 m away and confirmed links are not rejected for it.
TEST(ProjectRegistration, ScansFarFromTheirFilesOriginsRegisterAsNearThem) {
  const BunnyProject bunny(30.0);
  const std::vector<std::size_t> used{0, 1, 4, 5};  // bun000, bun045, bun315, chin
  std::vector<PointCloud> scans;
  for (std::size_t i : used) scans.push_back(bunny.scans[i]);
  const ProjectResult r = register_project(scans, statue_params());
  EXPECT_EQ(r.scans_registered, used.size());
  for (std::size_t k = 0; k < used.size(); ++k) {
    EXPECT_TRUE(r.scans[k].registered) << bunny.files[used[k]] << ": " << r.scans[k].reason;
    EXPECT_LT(rms_error_m(scans[k], r.scans[k].pose, bunny.truth[used[k]]), 0.001) << bunny.files[used[k]];
  }
  for (const ProjectLink& l : r.links)
    if (l.accepted) {
      EXPECT_LT(l.residual_m, 0.002) << l.source << "->" << l.target;
    }
}

TEST(ProjectRegistration, ScreenedPairsRegisterEachScanWithItsBestPartners) {
  const BunnyProject bunny;
  ProjectParams params = statue_params();
  params.pairs = PairSelection::kScreened;
  params.partners = 3;
  const ProjectResult r = register_project(bunny.scans, params);
  EXPECT_EQ(r.pairs_used, PairSelection::kScreened);
  EXPECT_EQ(r.pairs_screened, 15u);
  EXPECT_LT(r.links.size(), 15u);
  EXPECT_GE(r.links.size(), 6u);  // every scan in a pair, and the pairs connect them all
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_TRUE(r.scans[i].registered) << bunny.files[i] << ": " << r.scans[i].reason;
    EXPECT_LT(rms_error_m(bunny.scans[i], r.scans[i].pose, bunny.truth[i]), 0.001) << bunny.files[i];
  }
  EXPECT_TRUE(std::any_of(r.timings.begin(), r.timings.end(), [](const StageTiming& t) { return t.stage == "screen"; }));
  params.partners = 0;
  EXPECT_THROW(register_project(bunny.scans, params), Error);
}

// The screen that leaves no pair out leaves no link unchecked for want of loops: two scans have one pair,
// which no loop can check, and it is taken on its pairwise verdict as with all pairs.
TEST(ProjectRegistration, ScreenedLinkInNoLoopIsAcceptedWhereTheScreenLeftNoPairOut) {
  const BunnyProject bunny;
  ProjectParams params = statue_params();
  params.pairs = PairSelection::kScreened;
  const ProjectResult r = register_project({bunny.scans[0], bunny.scans[1]}, params);
  ASSERT_EQ(r.links.size(), 1u);
  EXPECT_TRUE(r.links[0].accepted) << r.links[0].reason;
  EXPECT_EQ(r.links[0].verdict, LinkVerdict::kUnchecked);
  EXPECT_TRUE(r.scans[1].registered) << r.scans[1].reason;
  EXPECT_LT(rms_error_m(bunny.scans[1], r.scans[1].pose, bunny.truth[1]), 0.001);
}

TEST(ProjectRegistration, ScanOfAnotherObjectIsNotRegisteredAndTheRestStill) {
  BunnyProject bunny;
  // A mirrored bunny: shaped like the others, but no rigid motion puts it on them.
  std::vector<Eigen::Vector3d> mirrored;
  for (const Eigen::Vector3f& p : bunny.scans[1].points) mirrored.push_back(Eigen::Vector3d(-p.x(), p.y(), p.z()) + bunny.scans[1].origin_m);
  std::vector<PointCloud> scans{bunny.scans[0], bunny.scans[1], bunny.scans[4], make_local_cloud(mirrored, {})};
  const ProjectResult r = register_project(scans, statue_params());
  EXPECT_FALSE(r.scans[3].registered);
  EXPECT_TRUE(r.scans[3].constraint.isZero()) << "an unregistered scan is pinned by nothing";
  for (std::size_t i : {0, 1, 2}) {
    EXPECT_TRUE(r.scans[i].registered) << i;
    const std::size_t original = i == 2 ? 4 : i;
    EXPECT_LT(rms_error_m(scans[i], r.scans[i].pose, bunny.truth[original]), 0.001) << i;
  }
  for (const ProjectLink& l : r.links)
    if (l.source == 3 || l.target == 3) {
      EXPECT_FALSE(l.accepted);
      EXPECT_FALSE(l.reason.empty());
    }
}

// A half turn about the y axis through the cloud's centroid (in its frame): a symmetric object's flip.
Eigen::Matrix4d half_turn_about_centroid(const PointCloud& cloud) {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& p : cloud.points) centre += p.cast<double>();
  centre = centre / static_cast<double>(cloud.size()) + cloud.origin_m;
  Eigen::Matrix4d turn = Eigen::Matrix4d::Identity();
  turn.topLeftCorner<3, 3>() = rotation_exp(Eigen::Vector3d(0, 3.14159265, 0));
  turn.topRightCorner<3, 1>() = centre - turn.topLeftCorner<3, 3>() * centre;
  return turn;
}

// Registers each pair here, but one pair's 4PCS "misses" its truth: its hypotheses are replaced by the
// truth turned half about the target's y axis through its centroid, as a well-supported, confident winner.
class MissingTruthRunner : public PairRunner {
 public:
  MissingTruthRunner(ScanPair missed) : missed_(missed) {}
  void run(const std::vector<PreparedScan>& scans, const std::vector<ScanPair>& pairs, const RegistrationParams& params,
           const CancellationToken* cancel, const Done& done) override {
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      PairOutcome outcome = register_pair(scans[pairs[k].first], scans[pairs[k].second], params, cancel);
      if (pairs[k] == missed_ && outcome.result) {
        const Eigen::Matrix4d turn = half_turn_about_centroid(scans[pairs[k].second].cloud());
        RegistrationResult& r = *outcome.result;
        r.transform = turn * r.transform;
        r.hypotheses.resize(1);
        r.hypotheses[0].transform = r.transform;
        r.ambiguous = false;
        r.ambiguity_margin = 0.5;
        r.well_supported = true;
      }
      done(k, std::move(outcome));
    }
  }

 private:
  ScanPair missed_;
};

TEST(ProjectRegistration, PoseTheLoopsImplyReplacesAPairsConfidentWrongWinner) {
  const BunnyProject bunny;
  const std::vector<PointCloud> scans{bunny.scans[0], bunny.scans[1], bunny.scans[4]};  // bun000, bun045, bun315
  MissingTruthRunner runner({0, 2});
  const ProjectResult r = register_project(scans, statue_params(), nullptr, {}, {}, &runner);
  ASSERT_EQ(r.links.size(), 3u);
  const ProjectLink& fixed = r.links[1];  // 0 -> 2
  EXPECT_GE(fixed.judged_loop_poses, 1u);
  EXPECT_TRUE(fixed.loop_pose_won);
  EXPECT_TRUE(fixed.accepted) << fixed.reason;
  EXPECT_NE(fixed.reason.find("loops implied"), std::string::npos) << fixed.reason;
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_TRUE(r.scans[i].registered) << i << ": " << r.scans[i].reason;
    EXPECT_LT(rms_error_m(scans[i], r.scans[i].pose, bunny.truth[i == 2 ? 4 : i]), 0.001) << i;
  }
  EXPECT_TRUE(std::any_of(r.timings.begin(), r.timings.end(), [](const StageTiming& t) { return t.stage == "loop_poses"; }));
}

// Registers each pair here, but places scan 1 half-turned about its centroid against scan 2 as a confident
// winner, and against scan 0 as the runner-up of the true winner: the loop closes through that runner-up (a
// scan turned against all the others closes every loop), as the monument's back station did with its
// front-side neighbour.
class TurnedScanRunner : public PairRunner {
 public:
  void run(const std::vector<PreparedScan>& scans, const std::vector<ScanPair>& pairs, const RegistrationParams& params,
           const CancellationToken* cancel, const Done& done) override {
    const Eigen::Matrix4d turn = half_turn_about_centroid(scans[1].cloud());  // in scan 1's frame
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      PairOutcome outcome = register_pair(scans[pairs[k].first], scans[pairs[k].second], params, cancel);
      if (outcome.result && pairs[k] == ScanPair{0, 1}) {
        RegistrationResult& r = *outcome.result;
        r.hypotheses.resize(2);
        r.hypotheses[1] = r.hypotheses[0];
        r.hypotheses[1].transform = rigid_inverse(turn) * r.transform;
        r.ambiguity_margin = 0.08;
      } else if (outcome.result && pairs[k] == ScanPair{1, 2}) {
        RegistrationResult& r = *outcome.result;
        r.transform = r.transform * turn;
        r.hypotheses.resize(1);
        r.hypotheses[0].transform = r.transform;
        r.ambiguous = false;
        r.ambiguity_margin = 0.9;
        r.well_supported = true;
      }
      done(k, std::move(outcome));
    }
  }
};

TEST(ProjectRegistration, ScanTurnedAgainstAllOthersIsPlacedByWhatTheWinnersImply) {
  const BunnyProject bunny;
  const std::vector<PointCloud> scans(bunny.scans.begin(), bunny.scans.begin() + 3);
  TurnedScanRunner runner;
  const ProjectResult r = register_project(scans, statue_params(), nullptr, {}, {}, &runner);
  ASSERT_EQ(r.links.size(), 3u);
  EXPECT_TRUE(r.links[2].loop_pose_won) << r.links[2].reason;  // 1 -> 2: the pose scans 0's links imply
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_TRUE(r.scans[i].registered) << i << ": " << r.scans[i].reason;
    EXPECT_LT(rms_error_m(scans[i], r.scans[i].pose, bunny.truth[i]), 0.001) << i;
  }
}

// Registers each pair here, except that a search from scan 0's side finds nothing, as 4PCS can miss from the side
// whose keypoints its partner does not repeat.
class BlindFromScanZeroRunner : public PairRunner {
 public:
  void run(const std::vector<PreparedScan>& scans, const std::vector<ScanPair>& pairs, const RegistrationParams& params,
           const CancellationToken* cancel, const Done& done) override {
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      PairOutcome outcome;
      if (pairs[k].first == 0)
        outcome.error = Error(ErrorCode::kFailedPrecondition, "no alignment found (test: blind from scan 0's side)");
      else
        outcome = register_pair(scans[pairs[k].first], scans[pairs[k].second], params, cancel);
      searched.push_back(pairs[k]);
      done(k, std::move(outcome));
    }
  }
  std::vector<ScanPair> searched;
};

TEST(ProjectRegistration, PairsOfAnUnconfirmedScanAreSearchedAgainFromTheOtherSide) {
  const BunnyProject bunny;
  const std::vector<PointCloud> scans(bunny.scans.begin(), bunny.scans.begin() + 3);
  BlindFromScanZeroRunner runner;
  const ProjectResult r = register_project(scans, statue_params(), nullptr, {}, {}, &runner);
  // The reference's two pairs failed from its side, so no loop confirmed it: both were searched again from the
  // partners' side, and only they (1 -> 2 was confirmed by nothing either, but it found a well-supported pose).
  EXPECT_EQ(runner.searched, (std::vector<ScanPair>{{0, 1}, {0, 2}, {1, 2}, {1, 0}, {2, 0}}));
  ASSERT_EQ(r.links.size(), 3u);
  EXPECT_EQ(r.links[0].source, 1u);  // swapped: the well-supported side's result
  EXPECT_EQ(r.links[0].target, 0u);
  EXPECT_EQ(r.links[1].source, 2u);
  for (const ProjectLink& link : r.links) EXPECT_TRUE(link.accepted) << link.source << "->" << link.target << ": " << link.reason;
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_TRUE(r.scans[i].registered) << i << ": " << r.scans[i].reason;
    EXPECT_LT(rms_error_m(scans[i], r.scans[i].pose, bunny.truth[i]), 0.001) << i;
  }
}

TEST(ProjectRegistration, SameResultAtAnyThreadCount) {
  const BunnyProject bunny;
  std::vector<PointCloud> scans(bunny.scans.begin(), bunny.scans.begin() + 3);
  ProjectParams one = statue_params(), two = statue_params();
  one.pairwise.threads = 1;
  two.pairwise.threads = 2;
  const ProjectResult a = register_project(scans, one), b = register_project(scans, two);
  for (std::size_t i = 0; i < scans.size(); ++i) EXPECT_EQ(a.scans[i].pose, b.scans[i].pose) << i;
}

TEST(ProjectRegistration, ReferenceScanKeepsTheIdentity) {
  const BunnyProject bunny;
  std::vector<PointCloud> scans(bunny.scans.begin(), bunny.scans.begin() + 3);
  ProjectParams params = statue_params();
  params.reference = 1;
  const ProjectResult r = register_project(scans, params);
  EXPECT_EQ(r.reference, 1u);
  EXPECT_TRUE(r.scans[1].pose.isApprox(Eigen::Matrix4d::Identity()));
  // Against the truth re-expressed in scan 1's frame.
  const Eigen::Matrix4d to_scan1 = rigid_inverse(bunny.truth[1]);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_LT(rms_error_m(scans[i], r.scans[i].pose, to_scan1 * bunny.truth[i]), 0.001) << i;
}

TEST(ProjectRegistration, MalformedProjectsAreRefusedWithAReason) {
  const BunnyProject bunny;
  auto code_of = [](auto&& f) {
    try {
      f();
    } catch (const Error& e) {
      return e.code();
    }
    return ErrorCode::kInternal;
  };
  EXPECT_EQ(code_of([&] { register_project({}, statue_params()); }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code_of([&] { register_project({bunny.scans[0]}, statue_params()); }), ErrorCode::kInvalidArgument);
  ProjectParams bad_reference = statue_params();
  bad_reference.reference = 2;
  EXPECT_EQ(code_of([&] { register_project({bunny.scans[0], bunny.scans[1]}, bad_reference); }), ErrorCode::kInvalidArgument);
  ProjectParams bad_list = statue_params();
  bad_list.pairs = PairSelection::kList;
  bad_list.pair_list = {{0, 5}};
  EXPECT_EQ(code_of([&] { register_project({bunny.scans[0], bunny.scans[1]}, bad_list); }), ErrorCode::kInvalidArgument);
  CancellationToken cancelled;
  cancelled.cancel();
  EXPECT_EQ(code_of([&] { register_project({bunny.scans[0], bunny.scans[1]}, statue_params(), &cancelled); }),
            ErrorCode::kCancelled);
}

TEST(CandidatePairs, AllSequenceAndList) {
  EXPECT_EQ(candidate_pairs(4, PairSelection::kAll).size(), 6u);
  EXPECT_EQ(candidate_pairs(4, PairSelection::kSequence), (std::vector<ScanPair>{{0, 1}, {0, 2}, {1, 2}, {1, 3}, {2, 3}}));
  EXPECT_EQ(candidate_pairs(4, PairSelection::kList, {{3, 1}, {1, 3}, {0, 2}}), (std::vector<ScanPair>{{0, 2}, {1, 3}}));
  EXPECT_THROW(candidate_pairs(4, PairSelection::kList, {{2, 2}}), Error);
}

}  // namespace
}  // namespace k4reg
