// Loop-consistent selection: a wrong pairwise winner is replaced by the candidate that closes the loops,
// a link with no true candidate is rejected with the loops that contradict it, links no loop checks stand
// on their pairwise verdict.
#include <gtest/gtest.h>

#include "k4reg/geometry/rigid_motion.h"
#include "k4reg/project/loop_closure.h"

namespace k4reg {
namespace {

// Scans about their frames' origins, 10 m across.
const ScanExtent kTenMetres{Eigen::Vector3d::Zero(), 10.0};

Eigen::Matrix4d pose(double yaw, const Eigen::Vector3d& t) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = rotation_exp(Eigen::Vector3d(0, 0, yaw));
  m.topRightCorner<3, 1>() = t;
  return m;
}

// A half turn about the vertical through (5, 0): the symmetric room's flip.
const Eigen::Matrix4d kFlip = pose(3.14159265, Eigen::Vector3d(10, 0, 0));

struct Project {
  std::vector<Eigen::Matrix4d> truth{pose(0, {0, 0, 0}), pose(0.7, {2, 1, 0}), pose(1.9, {4, -1, 0.1}), pose(-2.5, {1, 3, 0})};
  std::vector<ScanExtent> radius = std::vector<ScanExtent>(4, kTenMetres);
  // source -> target under the truth
  Eigen::Matrix4d relative(std::size_t s, std::size_t t) const { return rigid_inverse(truth[t]) * truth[s]; }
  std::vector<LinkCandidates> all_pairs() const {
    std::vector<LinkCandidates> links;
    for (std::size_t s = 0; s < 4; ++s)
      for (std::size_t t = s + 1; t < 4; ++t) links.push_back({s, t, {relative(s, t)}, 0.05, false, 1.0, true, {}});
    return links;
  }
};

TEST(LoopClosure, ConsistentProjectConfirmsEveryLink) {
  const Project p;
  const LoopSelectionResult r = select_loop_consistent(p.all_pairs(), p.radius);
  EXPECT_EQ(r.loops_checked, 4u);  // the four triangles of four scans
  EXPECT_EQ(r.loops_inconsistent, 0u);
  for (const LinkSelection& s : r.links) {
    EXPECT_EQ(s.verdict, LinkVerdict::kConfirmed);
    EXPECT_EQ(s.candidate, 0);
    EXPECT_EQ(s.loops, 2);
    EXPECT_EQ(s.loops_closed, 2);
    EXPECT_LT(s.loop_residual_m, 1e-9);
  }
}

TEST(LoopClosure, FlippedWinnerIsReplacedByTheRunnerUpThatClosesTheLoops) {
  const Project p;
  std::vector<LinkCandidates> links = p.all_pairs();
  // Link 1 (scans 0 -> 2): the pairwise winner is the flip, the truth its runner-up; ambiguous or not.
  links[1].transforms = {kFlip * p.relative(0, 2), p.relative(0, 2)};
  links[1].ambiguous = false;
  const LoopSelectionResult r = select_loop_consistent(links, p.radius);
  EXPECT_EQ(r.links[1].candidate, 1);
  EXPECT_EQ(r.links[1].verdict, LinkVerdict::kConfirmed);
  EXPECT_EQ(r.loops_inconsistent, 0u);
}

TEST(LoopClosure, LinkWithoutATrueCandidateIsContradicted) {
  const Project p;
  std::vector<LinkCandidates> links = p.all_pairs();
  links[2].transforms = {kFlip * p.relative(0, 3), pose(0.3, {1, 0, 0}) * p.relative(0, 3)};
  const LoopSelectionResult r = select_loop_consistent(links, p.radius);
  EXPECT_EQ(r.links[2].verdict, LinkVerdict::kContradicted);
  EXPECT_EQ(r.links[2].candidate, -1);
  EXPECT_FALSE(r.links[2].accepted());
  EXPECT_EQ(r.links[2].loops_closed, 0);
  EXPECT_GT(r.links[2].loop_residual_m, 1.0);
  EXPECT_EQ(r.loops_inconsistent, 2u);
  for (std::size_t l : {0, 1, 3, 4, 5}) EXPECT_TRUE(r.links[l].accepted()) << l;
}

TEST(LoopClosure, ErrorsWithinToleranceCloseTheLoop) {
  const Project p;
  std::vector<LinkCandidates> links = p.all_pairs();
  links[0].transforms[0] = pose(0.001, {0.02, 0, 0}) * links[0].transforms[0];  // 2 cm and 1 mrad x 10 m: ~2.2 cm
  EXPECT_EQ(select_loop_consistent(links, p.radius).loops_inconsistent, 0u);
  links[0].transforms[0] = pose(0.0, {0.5, 0, 0}) * p.relative(0, 1);  // far beyond 3 x sqrt(3) x 5 cm
  const LoopSelectionResult r = select_loop_consistent(links, p.radius);
  EXPECT_EQ(r.links[0].verdict, LinkVerdict::kContradicted);
}

TEST(LoopClosure, WithoutLoopsThePairwiseVerdictDecides) {
  const Project p;
  std::vector<LinkCandidates> chain{{0, 1, {p.relative(0, 1)}, 0.05, false, 1.0, true, {}},
                                    {1, 2, {p.relative(1, 2)}, 0.05, true, 1.0, true, {}},
                                    {2, 3, {}, 0.05, false, 1.0, true, {}}};
  const LoopSelectionResult r = select_loop_consistent(chain, p.radius);
  EXPECT_EQ(r.loops_checked, 0u);
  EXPECT_EQ(r.links[0].verdict, LinkVerdict::kUnchecked);
  EXPECT_TRUE(r.links[0].accepted());
  EXPECT_EQ(r.links[1].verdict, LinkVerdict::kUnresolved);
  EXPECT_FALSE(r.links[1].accepted());
  EXPECT_EQ(r.links[2].verdict, LinkVerdict::kFailed);
  EXPECT_EQ(r.links[0].loop_residual_m, -1.0);
}

TEST(LoopClosure, ScanThatOverlapsNothingLosesAllItsLinks) {
  // Scan 3's links are confident guesses that disagree with each other; the other three close their loop.
  const Project p;
  std::vector<LinkCandidates> links = p.all_pairs();
  links[2].transforms = {pose(1.0, {7, 7, 0})};   // 0 -> 3
  links[4].transforms = {pose(-2.0, {-5, 2, 0})};  // 1 -> 3
  links[5].transforms = {pose(0.4, {3, -9, 1})};   // 2 -> 3
  const LoopSelectionResult r = select_loop_consistent(links, p.radius);
  for (std::size_t l : {2, 4, 5}) EXPECT_EQ(r.links[l].verdict, LinkVerdict::kContradicted) << l;
  for (std::size_t l : {0, 1, 3}) EXPECT_EQ(r.links[l].verdict, LinkVerdict::kConfirmed) << l;
}

// In a symmetric room every pair is ambiguous, and two links turned by the symmetry close a loop as well
// as the truth: a loop confirms only where the two smallest margins add up to what one pair needs.
TEST(LoopClosure, AmbiguousLinksConfirmEachOtherOnlyWithEnoughMarginBetweenThem) {
  const Project p;
  for (const auto& [margin, confirmed] : {std::pair{0.03, true}, std::pair{0.02, false}}) {
    std::vector<LinkCandidates> links = p.all_pairs();
    for (LinkCandidates& l : links) l.ambiguous = true, l.margin = margin;
    const LoopSelectionResult r = select_loop_consistent(links, p.radius);
    for (const LinkSelection& s : r.links) {
      EXPECT_EQ(s.verdict, confirmed ? LinkVerdict::kConfirmed : LinkVerdict::kConsistent) << margin;
      EXPECT_EQ(s.loops_closed, confirmed ? 2 : 0) << margin;
    }
    EXPECT_EQ(r.loops_inconsistent, 0u);
  }
}

TEST(LoopClosure, PoorlySupportedWinnersVouchForNothing) {
  // Scan 3 is placed the same wrong way by both of its doubtful links (a symmetric object seen from one
  // side): their loop closes, yet proves nothing.
  const Project p;
  std::vector<LinkCandidates> links = p.all_pairs();
  // Each of scan 3's links puts it flipped about scan 0's frame: consistent among themselves.
  for (std::size_t l : {2, 4, 5}) {
    const std::size_t s = links[l].source;
    links[l].transforms = {rigid_inverse(kFlip * p.truth[3]) * p.truth[s]};
    links[l].ambiguous = true;
    links[l].well_supported = false;
    links[l].margin = 0.2;
  }
  const LoopSelectionResult r = select_loop_consistent(links, p.radius);
  // Their loops close, so they stay consistent; only the scan's strength (scan_strength.h) can refuse it.
  for (std::size_t l : {2, 4, 5}) {
    EXPECT_EQ(r.links[l].verdict, LinkVerdict::kConsistent) << l;
    EXPECT_EQ(r.links[l].loops_closed, 0) << l;
  }
  for (std::size_t l : {0, 1, 3}) EXPECT_EQ(r.links[l].verdict, LinkVerdict::kConfirmed) << l;
}

// Two true, well-supported links around an open loop imply the truth for the third, which its own 4PCS
// missed; a closed loop, or one whose other links are not well supported, implies nothing.
TEST(LoopClosure, OpenLoopsImplyTheirLinksPosesFromTheOtherTwo) {
  const Project p;
  std::vector<LinkCandidates> links = p.all_pairs();
  links[1].transforms = {kFlip * p.relative(0, 2)};  // 0 -> 2: no true candidate
  const LoopSelectionResult selection = select_loop_consistent(links, p.radius);
  const std::vector<std::vector<Eigen::Matrix4d>> implied = poses_implied_by_open_loops(links, selection, p.radius);
  ASSERT_EQ(implied.size(), links.size());
  // 0 -> 2 lies in triangles 0-1-2 and 0-2-3, each of which implies the truth once (then it is known).
  ASSERT_EQ(implied[1].size(), 1u);
  EXPECT_LT(displacement_m(rigid_inverse(p.relative(0, 2)) * implied[1][0], kTenMetres), 1e-9);
  // The other links of those open triangles are offered poses made with the flip, never the truth they have.
  for (std::size_t l : {0, 3, 2, 5})
    for (const Eigen::Matrix4d& pose : implied[l]) EXPECT_GT(displacement_m(rigid_inverse(p.relative(links[l].source, links[l].target)) * pose, kTenMetres), 1.0);
  EXPECT_TRUE(implied[4].empty());  // 1 -> 3: its triangle 1-2-3 closes

  const auto closed = poses_implied_by_open_loops(p.all_pairs(), select_loop_consistent(p.all_pairs(), p.radius), p.radius);
  for (const auto& poses : closed) EXPECT_TRUE(poses.empty());

  for (std::size_t l : {0, 2, 3, 5}) links[l].well_supported = false;  // every partner of 0 -> 2 in doubt
  EXPECT_TRUE(poses_implied_by_open_loops(links, selection, p.radius)[1].empty());
}

// A scan turned against all the others closes every loop: here scan 1, by the runner-up of its confident
// true link to scan 0 and the confident wrong winner of its link to scan 2 (the monument's back station and
// its front-side neighbour). The winners do not close, so they imply the truth for each link whose truth
// neither hypothesis has, to be judged on that pair's clouds.
TEST(LoopClosure, LoopsClosedOnlyThroughARunnerUpImplyWhatTheWinnersGive) {
  const Project p;
  const Eigen::Matrix4d turned = kFlip * p.relative(0, 1);  // scan 1 half-turned in scan 0's frame
  std::vector<LinkCandidates> links{{0, 1, {p.relative(0, 1), turned}, 0.05, false, 0.08, true, {}},
                                    {0, 2, {p.relative(0, 2)}, 0.05, false, 0.3, true, {}},
                                    {1, 2, {p.relative(0, 2) * rigid_inverse(turned)}, 0.05, false, 0.9, true, {}}};
  const LoopSelectionResult selection = select_loop_consistent(links, p.radius);
  ASSERT_EQ(selection.links[0].candidate, 1);  // the loop closes through the runner-up
  const std::vector<std::vector<Eigen::Matrix4d>> implied = poses_implied_by_open_loops(links, selection, p.radius);
  ASSERT_EQ(implied[2].size(), 1u);
  EXPECT_LT(displacement_m(rigid_inverse(p.relative(1, 2)) * implied[2][0], kTenMetres), 1e-9);
  EXPECT_TRUE(implied[0].empty());  // what the other two winners imply for 0 -> 1 is its runner-up: known
  EXPECT_EQ(implied[1].size(), 1u);  // 0 -> 2 is offered the turned pose, for its clouds to reject

  links[2].transforms = {p.relative(1, 2)};  // the winners close: nothing to imply
  const LoopSelectionResult closed = select_loop_consistent(links, p.radius);
  for (const auto& poses : poses_implied_by_open_loops(links, closed, p.radius)) EXPECT_TRUE(poses.empty());
}

// A pair's clouds judge its winner against the poses its loops implied: an implied pose that wins replaces it; one
// the clouds cannot tell from the winner (within the ambiguity margin, second) makes the link a tie for the loops
// to decide; otherwise the winner stands.
TEST(LoopClosure, ImpliedPosesWinTieOrLoseOnThePairsClouds) {
  const Project p;
  const Eigen::Matrix4d truth = p.relative(0, 1), winner = kFlip * truth;
  const LinkCandidates link{0, 1, {winner}, 0.05, false, 0.3, true, {}};
  auto judged = [&](const Eigen::Matrix4d& first, const Eigen::Matrix4d& second, double second_refined, double margin) {
    RegistrationResult r;
    r.transform = first;
    r.hypotheses.resize(2);
    r.hypotheses[0].transform = first;
    r.hypotheses[0].refined_score = 0.998;
    r.hypotheses[1].transform = second;
    r.hypotheses[1].refined_score = second_refined;
    r.ambiguity_margin = margin;
    return r;
  };
  const Eigen::Matrix4d nudged = pose(0.001, {0.01, 0, 0}) * truth;  // refined a little away from the implied pose
  EXPECT_EQ(judge_implied_poses(link, {truth}, judged(nudged, winner, 0.8, 0.2), p.radius), LoopPoseJudgement::kImpliedWon);
  EXPECT_EQ(judge_implied_poses(link, {truth}, judged(winner, nudged, 0.997, 0.001), p.radius), LoopPoseJudgement::kTied);
  EXPECT_EQ(judge_implied_poses(link, {truth}, judged(winner, nudged, 0.7, 0.3), p.radius), LoopPoseJudgement::kWinnerStands);
  // A close runner-up that is not an implied pose (a twin the guard added) is no tie with the loops.
  EXPECT_EQ(judge_implied_poses(link, {truth}, judged(winner, pose(2.0, {5, 5, 0}), 0.997, 0.001), p.radius),
            LoopPoseJudgement::kWinnerStands);
  // A runner-up not refined (outside the contender band) ties nothing.
  EXPECT_EQ(judge_implied_poses(link, {truth}, judged(winner, nudged, 0.0, 0.001), p.radius), LoopPoseJudgement::kWinnerStands);
}

}  // namespace
}  // namespace k4reg
