// Project registration: N scans into one frame (after Theiler, Wegner, Schindler 2015), top to bottom:
//   candidate pairs (candidate_pairs.h; for large projects each scan's best partners, partner_screen.h)
//   ->  pairwise K-4PCS per pair, keeping its distinct hypotheses (screened: then the next best partners of scans
//   no loop confirms)  ->  the pairs of scans no loop confirms that found no well-supported pose, searched again
//   with the scans swapped (4PCS draws its bases in the source)  ->  links whose well-supported winner has a small
//   margin judged from both sides (two_sided_margin.h)
//   ->  loop-consistent selection of one hypothesis per link (loop_closure.h)  ->  where a loop stays open,
//   the poses its links imply judged on each link's own clouds (judge_poses), and the selection again
//   ->  initial poses by consensus of the accepted links, from the reference out  ->  conflicts, minority
//   placements (scan_conflicts.h) and each scan's strength (scan_strength.h, twin_motion.h)  ->  global refinement
//   (pose_graph.h), where a link that disagrees with the refined project is dropped and the rest solved again.
// A scan that no majority of accepted links places, or that they hold too weakly to tell it from a
// symmetric twin, is reported as not registered, never forced into place. Pairs run one after the other, each on all
// threads (or wherever a PairRunner sends them), so the result is the same at any thread count and on any runner.
// Cost: for screened pairs, one 4PCS round on keypoints per pair of scans (about 0.1 s at 1 M points); one
// pairwise registration per candidate pair (0.2-3 s each at 1 M points on 2 cores), and one more per pair searched
// from the other side (none where every scan closes a loop); judging implied
// poses, a guard and a verdict per link in an open loop of well-supported links (0.1-1 s each), and as much per
// weak link judged from both sides (2-4 s at 0.7 M points); selection and refinement take milliseconds.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "k4reg/geometry/point_cloud.h"
#include "k4reg/project/candidate_pairs.h"
#include "k4reg/project/pair_runner.h"
#include "k4reg/registration/registration.h"
#include "k4reg/util/cancellation.h"

namespace k4reg {

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
  std::string verdict;  // confirmed, unchecked, contradicted, unresolved, failed, inconsistent
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
double link_tolerance_m(const ProjectLink& link);

// Called after each pair: the link as registered (before selection), how many pairs finished before it and the
// number of pairs.
using PairCallback = std::function<void(const ProjectLink& link, std::size_t index, std::size_t pairs)>;

// Throws kInvalidArgument for fewer than 2 scans, an empty scan, a reference out of range, partners 0 or bad
// pairwise parameters; kCancelled / kDeadlineExceeded when stopped (time_budget_s of the pairwise parameters bounds
// the whole project). A pair that cannot be registered is a failed link, not an error.
// `runner` registers the pairs (pair_runner.h); null = one after the other in this process. The poses do not
// depend on it.
ProjectResult register_project(const std::vector<PointCloud>& scans, const ProjectParams& params,
                               const CancellationToken* cancel = nullptr, const ProgressCallback& progress = {},
                               const PairCallback& on_pair = {}, PairRunner* runner = nullptr);

}  // namespace k4reg
