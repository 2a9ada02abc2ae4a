// A confident pairwise result that the project contradicts refuses its scans (never the reference) unless their
// accepted links outnumber such results; doubtful, accepted or agreeing links refuse nothing.
#include <gtest/gtest.h>

#include "k4reg/geometry/rigid_motion.h"
#include "k4reg/project/scan_conflicts.h"

namespace k4reg {
namespace {

Eigen::Matrix4d shifted(double x) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m(0, 3) = x;
  return m;
}

// Three placed scans along x; links 0 -> 1, 1 -> 2 (accepted) and 0 -> 2 (rejected), all agreeing.
ProjectResult placed_project() {
  ProjectResult r;
  r.scans.resize(3);
  for (std::size_t i = 0; i < 3; ++i) r.scans[i].registered = true, r.scans[i].pose = shifted(2.0 * i);
  for (auto [s, t, accepted] : {std::tuple{0, 1, true}, std::tuple{1, 2, true}, std::tuple{0, 2, false}}) {
    ProjectLink link;
    link.source = s, link.target = t, link.accepted = accepted;
    link.transform = rigid_inverse(r.scans[t].pose) * r.scans[s].pose;
    link.well_supported = true;
    link.verdict = accepted ? LinkVerdict::kConfirmed : LinkVerdict::kContradicted;
    link.min_scale_m_used = 0.05;  // tolerance 3 x 0.1 m
    r.links.push_back(link);
  }
  return r;
}

TEST(ScanConflicts, AgreeingLinksRefuseNothing) {
  ProjectResult r = placed_project();
  refuse_conflicted_scans(r, std::vector<ScanExtent>(3, {Eigen::Vector3d::Zero(), 10.0}));
  for (const ProjectScan& s : r.scans) EXPECT_TRUE(s.registered);
}

TEST(ScanConflicts, ConfidentRejectedLinkThatDisagreesRefusesBothScansButTheReference) {
  ProjectResult r = placed_project();
  r.links[2].transform = shifted(1.0) * r.links[2].transform;  // 1 m off, confident
  refuse_conflicted_scans(r, std::vector<ScanExtent>(3, {Eigen::Vector3d::Zero(), 10.0}));
  EXPECT_TRUE(r.scans[0].registered);  // the reference
  EXPECT_TRUE(r.scans[1].registered);
  EXPECT_FALSE(r.scans[2].registered);
  EXPECT_NE(r.scans[2].reason.find("link 2 (0 -> 2)"), std::string::npos) << r.scans[2].reason;
}

// Scan 2 held by two accepted links (1 -> 2 and a fourth scan's 2 -> 3) against the one confident link that
// contradicts it: the one link is outvoted, and no scan leaves.
TEST(ScanConflicts, AScanItsAcceptedLinksHoldMoreFirmlyThanTheContradictingOnesStays) {
  ProjectResult r = placed_project();
  r.scans.push_back(r.scans[2]);
  r.scans[3].pose = shifted(6.0);
  ProjectLink extra = r.links[1];
  extra.source = 2, extra.target = 3;
  extra.transform = rigid_inverse(r.scans[3].pose) * r.scans[2].pose;
  r.links.push_back(extra);
  r.links[2].transform = shifted(1.0) * r.links[2].transform;  // 1 m off, confident
  refuse_conflicted_scans(r, std::vector<ScanExtent>(4, {Eigen::Vector3d::Zero(), 10.0}));
  for (const ProjectScan& s : r.scans) EXPECT_TRUE(s.registered) << s.reason;
}

TEST(ScanConflicts, DoubtfulOrAcceptedOrSmallMisfitsRefuseNothing) {
  for (int variant = 0; variant < 4; ++variant) {
    ProjectResult r = placed_project();
    ProjectLink& link = r.links[2];
    link.transform = shifted(variant == 3 ? 0.2 : 1.0) * link.transform;  // 0.2 m: within 0.3 m
    if (variant == 0) link.ambiguous = true;
    if (variant == 1) link.well_supported = false;
    if (variant == 2) link.accepted = true;
    refuse_conflicted_scans(r, std::vector<ScanExtent>(3, {Eigen::Vector3d::Zero(), 10.0}));
    for (const ProjectScan& s : r.scans) EXPECT_TRUE(s.registered) << variant;
  }
}

// A scan held by one link while three of its accepted links lead to refused scans is refused, and so is one
// that the refusal leaves in the minority in turn; a scan whose links mostly lead to placed scans stays.
TEST(ScanConflicts, ScansPlacedOnAMinorityOfTheirLinksAreRefused) {
  ProjectResult r;
  r.scans.resize(7);
  for (ProjectScan& s : r.scans) s.registered = true;
  for (std::size_t refused : {4, 5, 6}) r.scans[refused].registered = false;
  // 0-1, 1-2, 0-2 placed together; 3 held by 0 only, its other links to the refused 4, 5, 6; 2 also links to 3.
  for (auto [s, t] : {std::pair{0, 1}, {1, 2}, {0, 2}, {0, 3}, {3, 4}, {3, 5}, {3, 6}, {2, 3}}) {
    ProjectLink link;
    link.source = s, link.target = t, link.accepted = true;
    r.links.push_back(link);
    r.scans[s].links.push_back(r.links.size() - 1);
    r.scans[t].links.push_back(r.links.size() - 1);
  }
  refuse_minority_placements(r);
  EXPECT_TRUE(r.scans[0].registered && r.scans[1].registered && r.scans[2].registered);
  EXPECT_FALSE(r.scans[3].registered);  // 2 of its 5 links lead to placed scans
  EXPECT_NE(r.scans[3].reason.find("3 of its 5 accepted links"), std::string::npos) << r.scans[3].reason;

  // Now 2 has links to 1, 0 and the refused 3: still a majority. Take 1 away and it is left with 1 of 3.
  r.scans[1].registered = false;
  refuse_minority_placements(r);
  EXPECT_FALSE(r.scans[2].registered);
  EXPECT_TRUE(r.scans[0].registered);  // the reference stays
}

}  // namespace
}  // namespace k4reg
