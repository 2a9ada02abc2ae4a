// What a project registration takes and gives (register_project, project_registration.h), and what its stages
// pass along: its parameters, its links (one per registered pair), its scans and the result.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "k4reg/geometry/rigid_motion.h"
#include "k4reg/project/candidate_pairs.h"
#include "k4reg/registration/prepared_scan.h"
#include "k4reg/registration/registration.h"
#include "k4reg/util/cancellation.h"

namespace k4reg {

// What the loops, the placement and the refinement made of a link.
enum class LinkVerdict {
  kConfirmed,     // its chosen candidate closes at least one loop
  kConsistent,    // closes all its loops, though none vouches for it (a symmetric scene): accepted, and
                  // how firmly it holds its scans is left to scan_strength.h
  kUnchecked,     // in no loop; accepted on its pairwise verdict (unambiguous)
  kContradicted,  // closes no vouching loop, and an open loop blames it: rejected
  kUnresolved,    // ambiguous pairwise, and no loop resolves it (in none, or its loops stay open unblamed): rejected
  kFailed,        // pairwise registration found no candidate
  kInconsistent,  // accepted by its loops, then contradicted by the placement or the refined project: rejected
  kPending,       // registered, not judged yet (a link as a pair finishes, before the loops)
};

// Its name in the API (proto, JSON): confirmed, consistent, unchecked, contradicted, unresolved, failed, inconsistent,
// pending.
const char* to_string(LinkVerdict verdict);

// The verdict of an API name; kInvalidArgument for another.
LinkVerdict link_verdict_from_string(const std::string& name);

struct ProjectParams {
  // Per pair as in register_clouds: min_scale_m and overlap 0 = automatic (the defaults), seed, threads, ...
  // Every pair runs with this seed, so a link equals `k4reg align` on the same two scans.
  RegistrationParams pairwise;
  std::size_t reference = 0;  // the scan whose pose is the identity
  PairSelection pairs = PairSelection::kAuto;  // all pairs up to kAllPairsUpTo scans, screened beyond
  std::vector<ScanPair> pair_list;  // for PairSelection::kList
  std::size_t partners = 4;         // for PairSelection::kScreened: partners registered per scan (>= 1)
};

struct ProjectLink {
  std::size_t source = 0, target = 0;  // scan indices; transform maps source -> target
  Eigen::Matrix4d transform = Eigen::Matrix4d::Identity();  // the chosen hypothesis (identity when failed)
  // The pairwise result's figures (of its winner); see `candidate` for the hypothesis the loops chose.
  double rmse_m = 0.0, overlap = 0.0, cloud_score = 0.0, ambiguity_margin = 0.0;
  bool ambiguous = false, well_supported = false;
  double min_scale_m_used = 0.0, overlap_used = 0.0;
  // How firmly the surfaces of its pairwise refinement pin the translation, in the target scan's frame
  // (translation_constraint.h; the winner's, where the loops chose another candidate: a symmetric twin meets
  // the same surfaces).
  Eigen::Matrix3d constraint = Eigen::Matrix3d::Zero();
  std::size_t hypotheses = 0;  // distinct candidates the pairwise registration kept
  // Poses its open loops implied that its own clouds judged alongside its hypotheses (loop_closure.h), and
  // whether one of them won: the figures above are then that judgement's, else the pairwise result's.
  std::size_t judged_loop_poses = 0;
  bool loop_pose_won = false;
  // Where its pairwise winner was well supported but its margin small: judged from the target's side as well
  // (two_sided_margin.h), that side's margin of its first candidate over the second (signed), the two sides'
  // margins added (what the loops and the scans' strength use), and whether the two sides together preferred
  // the pairwise runner-up, which then became its first candidate (and cloud_score is the runner-up's).
  bool reverse_judged = false, runner_up_preferred = false;
  double reverse_margin = 0.0, two_sided_margin = 0.0;
  int candidate = -1;          // the one chosen (0 = the pairwise winner, or the runner-up both sides preferred), -1 = none
  bool accepted = false;
  LinkVerdict verdict = LinkVerdict::kPending;
  std::string reason;   // why not accepted (or how it was accepted), in words
  int loops = 0, loops_closed = 0;
  double loop_residual_m = -1.0;  // smallest residual of its loops (m); -1 = in no loop
  double residual_m = -1.0;       // misfit after the global refinement (m); -1 = not in it
  double seconds = 0.0;           // its pairwise registration
};

struct ProjectScan {
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();  // p_project = pose * p_scan (files' frames)
  bool registered = false;
  std::vector<std::size_t> links;  // accepted links touching it (indices into ProjectResult::links)
  std::size_t points = 0;
  // How firmly the accepted links hold it to the reference beyond what symmetry can copy (scan_strength.h,
  // twin_motion.h), capped at 1; under kAmbiguousMargin it is not registered.
  double strength = 0.0;
  std::string reason;  // why not registered, in words
  // Held too weakly to tell from a twin placement (0 < strength < kAmbiguousMargin): not registered, but the
  // evidence's two answers are given. candidate_poses: where its links place it (what the evidence prefers, by
  // `strength`), then where the cheapest twin motion takes it with the scans on its side of the cut
  // (twin_motion.h). As the links place them, not refined. Empty, and ambiguous false, otherwise.
  bool ambiguous = false;
  std::vector<Eigen::Matrix4d> candidate_poses;
  // How firmly its links in the refined project pin its translation, in the project's frame: their constraints
  // added and scaled to trace 3 (translation_constraint.h); zero when not registered or linked.
  Eigen::Matrix3d constraint = Eigen::Matrix3d::Zero();
  // Where its scanner stood, in its file's frame, and where that comes from (scanner_position.h).
  ScannerPosition scanner_position;
};

struct ProjectResult {
  std::vector<ProjectScan> scans;
  std::vector<ProjectLink> links;
  std::size_t reference = 0;
  PairSelection pairs_used = PairSelection::kAll;  // the selection the pairs came from (kAuto resolved)
  std::size_t pairs_screened = 0;                  // pairs whose overlap the screen estimated (kScreened)
  std::size_t scans_registered = 0;
  std::size_t loops_checked = 0, loops_inconsistent = 0;
  double global_rmse_m = 0.0;  // RMS of the accepted links' misfits after the global refinement
  // "screen" (kScreened), the pairwise stages summed over pairs, then "selection", "refinement"
  std::vector<StageTiming> timings;
};

// What a true link's transform can be off by (metres of scan displacement): its fine-scale error, or twice
// the scale it was found at.
inline double link_tolerance_m(const ProjectLink& link) { return std::max(2.0 * link.min_scale_m_used, link.rmse_m); }

// Called after each pair: the link as registered (before selection), how many pairs finished before it and the
// number of pairs.
using PairCallback = std::function<void(const ProjectLink& link, std::size_t index, std::size_t pairs)>;

// What every stage of a project reads: the prepared scans, where each one's points lie, the parameters each pair
// runs with (the project's deadline is in `cancel`) and where progress goes.
struct ProjectInputs {
  const std::vector<PreparedScan>& scans;
  const std::vector<ScanExtent>& extents;
  const RegistrationParams& pairwise;
  const CancellationToken* cancel;
  const ProgressCallback& progress;
};

}  // namespace k4reg
