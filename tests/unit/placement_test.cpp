// Initial poses by consensus (placement.h): a scan goes where most of its placed neighbours' links agree, at the
// proposal nearest the rest, and is placed again once more of its neighbours are placed.
#include "k4reg/project/placement.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "k4reg/geometry/rigid_motion.h"

namespace k4reg {
namespace {

Eigen::Matrix4d shifted(double x) { return Eigen::Affine3d(Eigen::Translation3d(x, 0.0, 0.0)).matrix(); }

// Links scans s and t by their true transform (tolerance 2 x min_scale_m), accepted and in both scans' lists.
void add_link(ProjectResult& r, const std::vector<Eigen::Matrix4d>& truth, std::size_t s, std::size_t t,
              double min_scale_m = 0.05) {
  ProjectLink link;
  link.source = s, link.target = t, link.accepted = true;
  link.transform = rigid_inverse(truth[t]) * truth[s];
  link.verdict = LinkVerdict::kConfirmed;
  link.min_scale_m_used = min_scale_m;
  link.loops_closed = 1;
  r.scans[s].links.push_back(r.links.size());
  r.scans[t].links.push_back(r.links.size());
  r.links.push_back(link);
}

// Five scans 2 m apart along x (truth), every pair among the first `linked` linked (tolerance 0.1 m each: two
// links agree within 3 x hypot(0.1, 0.1) = 0.42 m).
ProjectResult linked_project(std::vector<Eigen::Matrix4d>& truth, std::size_t linked = 5) {
  ProjectResult r;
  r.scans.resize(5);
  for (std::size_t i = 0; i < r.scans.size(); ++i) truth.push_back(shifted(2.0 * i));
  for (std::size_t s = 0; s < linked; ++s)
    for (std::size_t t = s + 1; t < linked; ++t) add_link(r, truth, s, t);
  return r;
}

// Link 0 (0 -> 1) 0.35 m off (within what two links' tolerances let agree, beyond what one link's allows), and
// closing the most loops, so that scan 1 is placed first, on it alone.
void misplace_scan_one_first(ProjectResult& r) {
  r.links[0].transform = shifted(0.35) * r.links[0].transform;
  r.links[0].loops_closed = 5;
}

const std::vector<ScanExtent> kExtents(5, {Eigen::Vector3d::Zero(), 10.0});

void expect_every_scan_at_its_truth(const ProjectResult& r, const std::vector<Eigen::Matrix4d>& truth) {
  for (std::size_t i = 0; i < r.scans.size(); ++i) {
    EXPECT_TRUE(r.scans[i].registered) << i;
    EXPECT_LT((r.scans[i].pose - truth[i]).norm(), 1e-9) << i;
  }
}

TEST(Placement, AgreeingLinksPlaceEveryScanWhereTheyPutIt) {
  std::vector<Eigen::Matrix4d> truth;
  ProjectResult r = linked_project(truth);
  place_by_consensus(r, kExtents);
  expect_every_scan_at_its_truth(r, truth);
}

// Scan 1 is placed first on its slightly wrong link to the reference. Once its other neighbours are placed, the
// proposals they agree on put it back where the true links do.
TEST(Placement, AScanPlacedFirstOnOneSlightlyWrongLinkIsPlacedAgainByAllItsNeighbours) {
  std::vector<Eigen::Matrix4d> truth;
  ProjectResult r = linked_project(truth);
  misplace_scan_one_first(r);
  place_by_consensus(r, kExtents);
  expect_every_scan_at_its_truth(r, truth);
}

// Scan 4 is linked to scans 1 and 3 only, by precise links (tolerance 0.02 m: they agree within 0.085 m). Scan 1
// is placed first, 0.35 m off, so the two disagree and scan 4 waits; once scan 1 is placed again by all its
// neighbours, they agree and scan 4 is placed.
TEST(Placement, AScanWaitingOnAMisplacedNeighbourIsPlacedOnceThatNeighbourMoves) {
  std::vector<Eigen::Matrix4d> truth;
  ProjectResult r = linked_project(truth, 4);
  add_link(r, truth, 1, 4, 0.01);
  add_link(r, truth, 3, 4, 0.01);
  misplace_scan_one_first(r);
  place_by_consensus(r, kExtents);
  expect_every_scan_at_its_truth(r, truth);
}

// A link far off (1 m) agrees with none of the others: the majority places its scan and outvotes it.
TEST(Placement, ALinkFarOffIsOutvoted) {
  std::vector<Eigen::Matrix4d> truth;
  ProjectResult r = linked_project(truth);
  r.links[5].transform = shifted(1.0) * r.links[5].transform;  // 1 -> 3
  place_by_consensus(r, kExtents);
  expect_every_scan_at_its_truth(r, truth);
}

// Scan 4's two links disagree by 1 m: no strict majority, so it is not placed, with a reason.
TEST(Placement, AScanWhoseLinksDisagreeIsNotPlaced) {
  std::vector<Eigen::Matrix4d> truth;
  ProjectResult r = linked_project(truth);
  for (std::size_t l = 0; l < r.links.size(); ++l) {
    const ProjectLink& link = r.links[l];
    if (link.target == 4 && link.source > 1) std::erase(r.scans[link.source].links, l), std::erase(r.scans[4].links, l);
  }
  r.links[3].transform = shifted(1.0) * r.links[3].transform;  // 0 -> 4; 1 -> 4 stays true
  place_by_consensus(r, kExtents);
  EXPECT_FALSE(r.scans[4].registered);
  EXPECT_FALSE(r.scans[4].reason.empty());
  for (std::size_t i = 0; i < 4; ++i) EXPECT_TRUE(r.scans[i].registered) << i;
}

}  // namespace
}  // namespace k4reg
