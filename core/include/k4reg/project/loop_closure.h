// Loop-consistent selection of pairwise results (after Theiler, Wegner, Schindler 2015): every link (scan
// pair) brings several distinct candidate transforms, best first; around every triangle of links the chosen
// candidates must compose to the identity. A link's candidate is chosen to close as many of its triangles
// as possible (iterated conditional modes: each link in turn takes the candidate that closes most triangles
// with the others' current choice, until nothing changes; ties keep the pairwise ranking, so the result is
// deterministic). A closed loop vouches for its links only where the cheapest other labelling that closes
// it as well is clearly worse: in a symmetric scene a loop with two links turned by the symmetry closes
// too, so the two smallest pairwise margins of the loop must add up to the margin one pair needs
// (kAmbiguousMargin). A link whose candidate is not its pairwise winner, or whose winner is poorly
// supported, counts with margin 0; a link confirmed by other loops counts as certain, so confirmation
// spreads from the clearest loops outwards. A candidate that closes a vouching loop is confirmed. A link
// that closes none is contradicted (rejected, with the reason) by an open loop that no doubtful link
// explains (see select_loop_consistent); one whose loops all close without vouching is consistent
// (accepted: the scans' strength decides).
// Cost: O(T * C) per round for T triangles and C candidates per link; T <= N^3 / 6 for N scans, so
// thousands of triangles for the all-pairs projects this is used on: milliseconds.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "k4reg/geometry/rigid_motion.h"
#include "k4reg/project/project_types.h"
#include "k4reg/registration/registration.h"

namespace k4reg {

struct LinkCandidates {
  std::size_t source = 0, target = 0;               // scan indices; transforms map source -> target
  std::vector<Eigen::Matrix4d> transforms;          // distinct candidates, the pairwise winner first; empty = failed
  double tolerance_m = 0.0;  // expected error of this link's true candidate (metres of scan displacement)
  bool ambiguous = false;    // the pairwise verdict on its winner
  double margin = 1.0;       // the pairwise ambiguity margin of its winner, against the free-space bar
                             // (margin_against_free_space_bar: ambiguity_margin.h)
  bool well_supported = true;  // its winner lies on the surface and explains what a true pose would
  std::vector<double> scores;  // per transform, its pairwise score (refined where it was refined); may be empty
  bool free_space_used = true;  // the pair was judged with the scanners' free space; else on geometry alone, and
                                // margins made from its scores count as margin_against_free_space_bar says
};


struct LinkSelection {
  int candidate = -1;         // index into transforms; -1 when rejected or failed
  LinkVerdict verdict = LinkVerdict::kFailed;
  int loops = 0;              // triangles through this link whose other two links have a candidate
  int loops_closed = 0;       // of those, closed with the chosen candidates and vouching for them
  double loop_residual_m = -1.0;  // smallest residual of its loops with the chosen candidates; -1 = no loop
  bool accepted() const {
    return verdict == LinkVerdict::kConfirmed || verdict == LinkVerdict::kConsistent || verdict == LinkVerdict::kUnchecked;
  }
};

struct LoopSelectionResult {
  std::vector<LinkSelection> links;  // one per input link, same order
  std::size_t loops_checked = 0;       // triangles whose three links have a candidate
  std::size_t loops_inconsistent = 0;  // of those, not closed with the final choice
};

// The loop residual tolerance of a triangle: three times the links' expected errors added in quadrature.
constexpr double kLoopToleranceFactor = 3.0;

// extents: per scan, where its points lie (centre and radius, its file's frame), at which a loop's residual is
// measured where the loop starts (displacement_m in rigid_motion.h).
LoopSelectionResult select_loop_consistent(const std::vector<LinkCandidates>& links,
                                           const std::vector<ScanExtent>& extents);

// Per link, the poses (source -> target) that its open triangles imply: where a triangle does not close with
// the chosen candidates (a rejected link's pairwise winner standing in for it), the other two links' choices
// composed, where both of those links' pairwise winners are well supported; and where it closes only through a
// runner-up while the pairwise winners do not close, the other two links' winners composed. A pair's 4PCS may
// miss its true pose, which two true links around a loop give; the pair's own clouds must then judge it
// (judge_poses), since a loop always closes with a link made from its other two.
// Poses within a link's tolerance of one of its candidates, or of one already implied, are left out.
std::vector<std::vector<Eigen::Matrix4d>> poses_implied_by_open_loops(const std::vector<LinkCandidates>& links,
                                                                     const LoopSelectionResult& selection,
                                                                     const std::vector<ScanExtent>& extents);

// Whether two poses of a link lie within three times its expected error of each other (displacement where its
// source scan is).
bool within_loop_tolerance(const LinkCandidates& link, const Eigen::Matrix4d& a, const Eigen::Matrix4d& b,
                           const std::vector<ScanExtent>& extents);

// What a pair's own clouds said of the poses its loops implied, from judge_poses' result on its winner and
// them: the winner stands, an implied pose won, or the clouds cannot tell an implied pose (second, within the
// ambiguity margin) from the winner, so the pair's own margin came from its 4PCS missing that pose.
enum class LoopPoseJudgement { kWinnerStands, kImpliedWon, kTied };
LoopPoseJudgement judge_implied_poses(const LinkCandidates& link, const std::vector<Eigen::Matrix4d>& implied,
                                      const RegistrationResult& judged, const std::vector<ScanExtent>& extents);

}  // namespace k4reg
