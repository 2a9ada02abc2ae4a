// The twin placement of a weakly held scan (twin_placement.h), on a hand-made project: three scans placed in a
// row, the link across the cut carrying a half turn as its runner-up.
#include <gtest/gtest.h>

#include "k4reg/geometry/rigid_motion.h"
#include "k4reg/project/twin_placement.h"

namespace k4reg {
namespace {

Eigen::Matrix4d pose(double yaw, double x, double y) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = rotation_exp(Eigen::Vector3d(0, 0, yaw));
  m.topRightCorner<3, 1>() = Eigen::Vector3d(x, y, 0);
  return m;
}

// A half turn about the vertical axis through (10, 6): the symmetry of a 20 x 12 m hall.
Eigen::Matrix4d hall_half_turn() { return pose(0, 10, 6) * pose(3.14159265358979, 0, 0) * pose(0, -10, -6); }

struct RowProject {
  ProjectResult project;
  std::vector<LinkCandidates> candidates;
  RowProject() {
    project.scans.resize(3);
    project.scans[0].pose = Eigen::Matrix4d::Identity();
    project.scans[1].pose = pose(0.3, 5, 1);
    project.scans[2].pose = pose(-1.2, 14, 9);
    // Link 0: scan 1 -> scan 0; link 1: scan 2 -> scan 1.
    for (auto [s, t] : {std::pair<std::size_t, std::size_t>{1, 0}, {2, 1}}) {
      ProjectLink& link = project.links.emplace_back();
      link.source = s, link.target = t, link.candidate = 0;
      const Eigen::Matrix4d truth = rigid_inverse(project.scans[t].pose) * project.scans[s].pose;
      // The runner-up puts the source where the hall's half turn takes it.
      const Eigen::Matrix4d twin = rigid_inverse(project.scans[t].pose) * hall_half_turn() * project.scans[s].pose;
      candidates.push_back({s, t, {truth, twin}, 0.0, true, 0.0, true, {1.0, 0.98}});
    }
  }
};

TEST(TwinPlacement, TheSideOfTheCutTurnsByTheRunnerUpOfTheLinkAcrossIt) {
  const RowProject row;
  // Scans 1 and 2 move together: link 0 crosses the cut, link 1 lies inside it.
  for (std::size_t scan : {1, 2}) {
    const std::optional<Eigen::Matrix4d> twin = twin_placement(row.project, row.candidates, {0, 1}, {1, 2}, scan);
    ASSERT_TRUE(twin);
    EXPECT_TRUE(twin->isApprox(hall_half_turn() * row.project.scans[scan].pose, 1e-9)) << scan;
  }
}

TEST(TwinPlacement, TheLinkWhoseOtherCandidateLosesLeastDecides) {
  RowProject row;
  // Scan 1 alone moves: links 0 (to 0) and 1 (to 2) both cross the cut. Link 1's runner-up is a shift, scored 0.5.
  row.candidates[1].transforms[1] = pose(0, 3, 0) * row.candidates[1].transforms[0];
  row.candidates[1].scores[1] = 0.5;
  const std::optional<Eigen::Matrix4d> twin = twin_placement(row.project, row.candidates, {0, 1}, {1}, 1);
  ASSERT_TRUE(twin);
  EXPECT_TRUE(twin->isApprox(hall_half_turn() * row.project.scans[1].pose, 1e-9));  // link 0's 0.98 beats 0.5
  // The other way round, link 1's candidate decides (scan 1 is link 1's target: its placement follows the inverse).
  row.candidates[1].scores[1] = 0.99;
  const std::optional<Eigen::Matrix4d> shifted = twin_placement(row.project, row.candidates, {0, 1}, {1}, 1);
  ASSERT_TRUE(shifted);
  const Eigen::Matrix4d expected = row.project.scans[2].pose * rigid_inverse(row.candidates[1].transforms[1]);
  EXPECT_TRUE(shifted->isApprox(expected, 1e-9));
}

TEST(TwinPlacement, NothingWhereNoLinkAcrossTheCutHasAnotherCandidate) {
  RowProject row;
  for (LinkCandidates& c : row.candidates) c.transforms.resize(1), c.scores.resize(1);
  EXPECT_FALSE(twin_placement(row.project, row.candidates, {0, 1}, {1, 2}, 2));
  EXPECT_FALSE(twin_placement(row.project, row.candidates, {}, {1, 2}, 2));  // no link used at all
}

}  // namespace
}  // namespace k4reg
