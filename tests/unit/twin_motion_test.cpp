// A scan's hold against one twin motion of its side of the cut (twin_motion.h), on a hand-made project shaped as
// hall layout 3 was measured: the reference's three links each lose least to another of the hall's half turns.
#include "k4reg/project/twin_motion.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>

#include "k4reg/geometry/rigid_motion.h"

namespace k4reg {
namespace {

Eigen::Matrix4d pose(const Eigen::Vector3d& rotation, const Eigen::Vector3d& translation) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = rotation_exp(rotation);
  m.topRightCorner<3, 1>() = translation;
  return m;
}

// The half turns of an 18.2 x 11.7 x 5.7 m hall about its three axes through its centre.
Eigen::Matrix4d half_turn(const Eigen::Vector3d& axis) {
  const Eigen::Vector3d centre(9.1, 5.85, 2.85);
  return pose(Eigen::Vector3d::Zero(), centre) * pose(3.14159265358979 * axis, Eigen::Vector3d::Zero()) *
         pose(Eigen::Vector3d::Zero(), -centre);
}
const Eigen::Matrix4d kVertical = half_turn(Eigen::Vector3d::UnitZ());
const Eigen::Matrix4d kAlongY = half_turn(Eigen::Vector3d::UnitY());  // floor onto ceiling
const Eigen::Matrix4d kAlongX = half_turn(Eigen::Vector3d::UnitX());

struct HallProject {
  ProjectResult project;
  std::vector<LinkCandidates> candidates;
  std::vector<ScanExtent> radius_m = std::vector<ScanExtent>(4, {Eigen::Vector3d::Zero(), 15.0});

  // floor_on_ceiling_close: that turn scores nearly as the truth on all three of station 0's links.
  explicit HallProject(bool floor_on_ceiling_close = false) {
    project.scans.resize(4);
    project.scans[1].pose = pose({0, 0, 2.1}, {16.6, 9.7, 1.5});
    project.scans[2].pose = pose({0, 0, -0.7}, {11.5, 6.0, 1.0});
    project.scans[3].pose = pose({0, 0, 1.3}, {1.9, 9.8, 1.5});
    for (ProjectScan& s : project.scans) s.registered = true;
    // Station 0's links: pairwise margins 0.020, 0.013, 0.017, each over another half turn; reverse margins as
    // measured. Per link the cut adds 0.049; moved as one, the scans lose at least 0.0587 (the vertical half turn).
    const double close = floor_on_ceiling_close ? 0.001 : 0.0;
    add({0, 1}, {0.9799, close > 0 ? 1.0 - close : 0.9663, 0.9705}, 1.0, 0.0014, LinkVerdict::kConsistent);
    add({0, 2}, {0.9770, close > 0 ? 1.0 - close : 0.9866, 0.9711}, 1.0, 0.0, LinkVerdict::kConsistent);
    add({0, 3}, {0.9795, close > 0 ? 0.9965 - close : 0.9791, 0.9644}, 0.9965, -0.0029, LinkVerdict::kConsistent);
    add({1, 2}, {0.9799, 0.9747, 0.9713}, 0.9997, 0.0248, LinkVerdict::kConfirmed);
    add({1, 3}, {0.9790, 0.9646, 0.9926}, 0.9988, 0.0241, LinkVerdict::kConfirmed);
    add({2, 3}, {0.9721, 0.9662, 0.9662}, 0.9986, 0.0106, LinkVerdict::kConfirmed);
  }
  // A link with the truth and the source moved by each half turn (vertical, along y, along x), scored so.
  void add(std::pair<std::size_t, std::size_t> scans, std::array<double, 3> twin_scores, double truth_score,
           double reverse_margin, LinkVerdict verdict) {
    const auto [s, t] = scans;
    LinkCandidates c{s, t, {}, 0.1, true, 0.0, true, {}};
    const Eigen::Matrix4d to_target = rigid_inverse(project.scans[t].pose);
    c.transforms.push_back(to_target * project.scans[s].pose);
    c.scores.push_back(truth_score);
    const std::array<Eigen::Matrix4d, 3> motions{kVertical, kAlongY, kAlongX};
    for (std::size_t k = 0; k < 3; ++k) {
      c.transforms.push_back(to_target * motions[k] * project.scans[s].pose);
      c.scores.push_back(twin_scores[k]);
    }
    // Best first, as a pair's candidates come.
    std::vector<std::size_t> order{1, 2, 3};
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return c.scores[a] > c.scores[b]; });
    LinkCandidates sorted{s, t, {c.transforms[0]}, c.tolerance_m, true, 0.0, true, {c.scores[0]}};
    for (std::size_t k : order) sorted.transforms.push_back(c.transforms[k]), sorted.scores.push_back(c.scores[k]);
    ProjectLink& link = project.links.emplace_back();
    link.source = s, link.target = t, link.candidate = 0, link.well_supported = true, link.accepted = true;
    link.verdict = verdict;
    link.ambiguity_margin = (sorted.scores[0] - sorted.scores[1]) / sorted.scores[0];
    link.reverse_judged = true;
    link.reverse_margin = reverse_margin;
    candidates.push_back(sorted);
  }
  std::vector<std::size_t> all_links() const { return {0, 1, 2, 3, 4, 5}; }
};

TEST(TwinMotion, ScansMovedAsOneLoseEachLinksMarginOverThatMotionsCandidate) {
  const HallProject hall;
  // The per-link cut: 0.0215 + 0.0134 + 0.0142.
  EXPECT_NEAR(link_weight(hall.project.links[0], hall.candidates[0]) +
                  link_weight(hall.project.links[1], hall.candidates[1]) +
                  link_weight(hall.project.links[2], hall.candidates[2]),
              0.0491, 1e-3);
  const std::vector<TwinHold> holds =
      holds_against_twins(hall.project, hall.candidates, hall.all_links(), hall.radius_m, 1.0);
  EXPECT_DOUBLE_EQ(holds[0].strength, 1.0);
  for (std::size_t i : {1, 2, 3}) {
    // Vertical: (0.0201 + 0.0014) + 0.0230 + (0.0171 - 0.0029); along y 0.0631, along x 0.0891.
    EXPECT_NEAR(holds[i].strength, 0.0587, 2e-4) << i;
    EXPECT_GE(holds[i].strength, kAmbiguousMargin) << i;
    EXPECT_EQ(holds[i].moves_with, (std::vector<std::size_t>{1, 2, 3})) << i;
    ASSERT_TRUE(holds[i].motion) << i;
    EXPECT_TRUE(holds[i].motion->isApprox(kVertical, 1e-9)) << i;
  }
}

TEST(TwinMotion, AMotionNoLinkTellsFromTheTruthKeepsTheScansWeakAndIsTheirTwin) {
  const HallProject hall(true);  // station 0's links: 0.0024 + 0.0010 + 0 over the floor-on-ceiling turn
  const std::vector<TwinHold> holds =
      holds_against_twins(hall.project, hall.candidates, hall.all_links(), hall.radius_m, 1.0);
  for (std::size_t i : {1, 2, 3}) {
    EXPECT_LT(holds[i].strength, kAmbiguousMargin) << i;
    ASSERT_TRUE(holds[i].motion) << i;
    EXPECT_TRUE(holds[i].motion->isApprox(kAlongY, 1e-9)) << i;  // the far side turns floor onto ceiling
  }
}

TEST(TwinMotion, NoLinkWithAnotherCandidateLeavesThePerLinkCutAndNoTwin) {
  HallProject hall;
  for (LinkCandidates& c : hall.candidates) c.transforms.resize(1), c.scores.resize(1);
  for (ProjectLink& link : hall.project.links) link.ambiguity_margin = 0.01, link.reverse_judged = false;
  for (std::size_t l : {3, 4, 5}) hall.project.links[l].verdict = LinkVerdict::kConfirmed;
  const std::vector<TwinHold> holds =
      holds_against_twins(hall.project, hall.candidates, hall.all_links(), hall.radius_m, 1.0);
  for (std::size_t i : {1, 2, 3}) {
    EXPECT_NEAR(holds[i].strength, 0.03, 1e-12) << i;
    EXPECT_FALSE(holds[i].motion) << i;
  }
}

TEST(TwinMotion, LinksJudgedOnGeometryAloneHoldAgainstTheirOwnBar) {
  // Station 0's three links each won by 0.05: with the scanners' free space, three independent margins that add
  // up to 0.15 hold scans 1-3 firmly; on geometry alone each is under the bar (kGeometryOnlyAmbiguousMargin), where
  // a symmetric scene's twin wins too, so together they hold nothing.
  for (const bool free_space : {true, false}) {
    HallProject hall;
    for (LinkCandidates& c : hall.candidates) c.transforms.resize(1), c.scores.resize(1), c.free_space_used = free_space;
    for (ProjectLink& link : hall.project.links) link.ambiguity_margin = 0.05, link.reverse_judged = false;
    const std::vector<TwinHold> holds =
        holds_against_twins(hall.project, hall.candidates, hall.all_links(), hall.radius_m, 1.0);
    for (std::size_t i : {1, 2, 3}) {
      EXPECT_NEAR(holds[i].strength, free_space ? 0.15 : 0.0, 1e-12) << i;
      EXPECT_EQ(holds[i].strength >= kAmbiguousMargin, free_space) << i;
    }
  }
}

TEST(TwinMotion, AMotionOneLinkAcrossNeverFoundIsNotATwin) {
  HallProject hall;
  // Station 0 -> 3 found none of the half turns (its runner-up a shift): no motion is offered by all three links
  // across, so the per-link cut stands.
  LinkCandidates& c = hall.candidates[2];
  const Eigen::Matrix4d shifted = pose(Eigen::Vector3d::Zero(), {4.8, 0, 0}) * c.transforms[0];
  c.transforms = {c.transforms[0], shifted};
  c.scores = {c.scores[0], 0.9795};
  const std::vector<TwinHold> holds =
      holds_against_twins(hall.project, hall.candidates, hall.all_links(), hall.radius_m, 1.0);
  for (std::size_t i : {1, 2, 3}) {
    EXPECT_NEAR(holds[i].strength, 0.0491, 1e-3) << i;
    EXPECT_FALSE(holds[i].motion) << i;
  }
}

}  // namespace
}  // namespace k4reg
