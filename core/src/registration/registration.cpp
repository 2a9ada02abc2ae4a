#include "k4reg/registration/registration.h"

#include <Eigen/Eigenvalues>
#include <fmt/format.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <optional>

#include "k4reg/registration/ambiguity_margin.h"
#include "k4reg/registration/contender_verdict.h"
#include "k4reg/registration/dog_keypoints.h"
#include "k4reg/registration/fine_polish.h"
#include "k4reg/registration/prepared_scan.h"
#include "k4reg/util/error.h"
#include "k4reg/util/stopwatch.h"
#include "k4reg/registration/four_pcs.h"
#include "k4reg/registration/free_space.h"
#include "k4reg/registration/icp.h"
#include "k4reg/registration/metrics.h"
#include "k4reg/geometry/neighbor_grid.h"
#include "k4reg/registration/pose_score.h"
#include "k4reg/geometry/rigid_fit.h"
#include "k4reg/geometry/rigid_motion.h"
#include "k4reg/geometry/sampling.h"
#include "k4reg/registration/surface_signal.h"
#include "k4reg/registration/symmetry_guard.h"
#include "k4reg/registration/translation_constraint.h"
#include "k4reg/geometry/voxel_grid.h"

namespace k4reg {
void validate(const RegistrationParams& p) {
  auto bad = [](const std::string& what) { fail(ErrorCode::kInvalidArgument, what); };
  if (!(p.min_scale_m == 0.0 || (p.min_scale_m >= 0.001 && p.min_scale_m <= 10.0)))
    bad("min_scale_m must be 0 (automatic) or in [0.001, 10] m");
  if (!(p.overlap == 0.0 || (p.overlap >= 0.05 && p.overlap <= 1.0))) bad("overlap must be 0 (automatic) or in [0.05, 1]");
  if (p.octaves < 1 || p.octaves > 8) bad("octaves must be in [1, 8]");
  if (p.scales_per_octave < 1 || p.scales_per_octave > 10) bad("scales_per_octave must be in [1, 10]");
  if (!(p.min_contrast >= 0.0 && p.min_contrast < 1.0)) bad("min_contrast must be in [0, 1)");
  if (p.max_bases < 0 || p.max_bases > 1000000) bad("max_bases must be in [0, 1e6]");
  if (p.hypotheses_kept < 1 || p.hypotheses_kept > 100) bad("hypotheses_kept must be in [1, 100]");
  if (p.icp_max_iterations < 0 || p.icp_max_iterations > 1000) bad("icp_max_iterations must be in [0, 1000]");
  if (p.threads < 0 || p.threads > 1024) bad("threads must be in [0, 1024]");
  // The budget becomes a deadline in 64-bit nanoseconds: 1e9 s (32 years) keeps that conversion in range.
  if (!(p.time_budget_s >= 0.0 && p.time_budget_s <= 1e9)) bad("time_budget_s must be in [0, 1e9] s");
  if (!(p.plain_voxel_m >= 0.0 && p.plain_voxel_m <= 100.0)) bad("plain_voxel_m must be in [0, 100] m");
}

namespace {

// Refuses clouds that cannot define a rigid transform: empty, a single point, a line or a plane.
void check_geometry(const std::vector<Eigen::Vector3f>& points, double scale_m, const char* name) {
  if (points.size() < 10)
    fail(ErrorCode::kInvalidArgument, std::string(name) + " cloud has " + std::to_string(points.size()) +
                                          " occupied voxels at the minimum scale; at least 10 are needed");
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : points) mean += p.cast<double>();
  mean /= points.size();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : points) cov += (p.cast<double>() - mean) * (p.cast<double>() - mean).transpose();
  cov /= points.size();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(cov, Eigen::EigenvaluesOnly);
  const Eigen::Vector3d spread = solver.eigenvalues().cwiseMax(0.0).cwiseSqrt();  // ascending
  if (spread(1) < scale_m)
    fail(ErrorCode::kInvalidArgument, std::string(name) + " cloud is degenerate: all points lie on a line");
  if (spread(0) < 0.5 * scale_m)
    fail(ErrorCode::kInvalidArgument, std::string(name) + " cloud is degenerate: all points lie on a plane");
}

// Whose free space judges the pair (params.free_space): kOn the scanners' (from the positions known, else the frames'
// origins), kOff none. kAuto: the scanners' where the sampling confirms both declared positions (scans in scanner
// coordinates, or with their poses: no search); else the scanners' where both positions are found from the sampling
// and could be terrestrial scanners' (scanner_position.h); else the cameras' where both are single views of an
// object; else none. A scanner found in the sampling, among its points, is the one that took them; the single-view
// rule reads the normals only, and a terrestrial scan facing one facade can pass it (courtyard stations 9 and 10 at
// 0.1 m, in arbitrary frames: judged as camera views, no pose was well supported until 0.05 m, 12x the time).
enum class FreeSpaceFrom { kNothing, kScanners, kCameras };
FreeSpaceFrom free_space_from(FreeSpaceCheck check, const PreparedScan& source, const PreparedScan& target, double sigma,
                              const CancellationToken* cancel) {
  if (check != FreeSpaceCheck::kAuto) return check == FreeSpaceCheck::kOn ? FreeSpaceFrom::kScanners : FreeSpaceFrom::kNothing;
  if (source.declared_scanner(cancel).source != ScannerSource::kNone &&
      target.declared_scanner(cancel).source != ScannerSource::kNone)
    return FreeSpaceFrom::kScanners;
  if (source.scanner_surrounded(cancel) && target.scanner_surrounded(cancel)) return FreeSpaceFrom::kScanners;
  return source.view_direction(sigma, cancel) && target.view_direction(sigma, cancel) ? FreeSpaceFrom::kCameras
                                                                                      : FreeSpaceFrom::kNothing;
}

// The voxel spacing at which a cloud keeps about `points` voxels (the paper's plain-4PCS baseline).
double spacing_for_count(const PointCloud& voxels, double start_m, std::size_t points) {
  double spacing = start_m;
  for (int step = 0; step < 40 && voxel_grid(voxels, spacing).cloud.size() > points; ++step) spacing *= 1.25;
  return spacing;
}

// The outcome of steps 2-4 for one keypoint signal and one round of bases.
struct CoarseAlignment {
  std::string signal;
  std::size_t source_keypoints = 0, target_keypoints = 0;
  const std::vector<Eigen::Vector3f>* source_points = nullptr;  // what 4PCS matched (local frames)
  const std::vector<Eigen::Vector3f>* target_points = nullptr;
  int bases_tried = 0;
  double overlap = 0.0;  // whose bases found it
  SymmetryGuardResult guarded;
  const Hypothesis& best() const { return guarded.hypotheses.front(); }
};

// The point sets 4PCS runs on, per keypoint signal (computed once, used by every round of bases).
struct PointSets {
  std::string signal;
  std::vector<Eigen::Vector3f> source, target;
  std::vector<std::uint8_t> source_labels, target_labels;  // DoG extremum: 1 maximum, 0 minimum
};

// Source -> target in the files' frames from the transform between the local (origin-shifted) frames.
Eigen::Matrix4d to_file_frames(const Eigen::Matrix4d& local, const Eigen::Vector3d& source_origin,
                               const Eigen::Vector3d& target_origin) {
  Eigen::Matrix4d t = local;
  t.topRightCorner<3, 1>() += target_origin - local.topLeftCorner<3, 3>() * source_origin;
  return t;
}

// Without free space (objects) a true pose explains about the overlap: well supported, and the search
// for more stops, at min(0.6, 0.75 x overlap). With free space the points the target scanner could not
// see are no evidence either way, so a true pose explains nearly all the rest (kWellSupportedWithFreeSpace,
// symmetry_guard.h).
// Without free space, an intensity pose below this meets the geometric signal's best.
constexpr double kSignalFallback = 0.6;
// With free space an intensity pose below what true poses reach leaves room for a better one: the geometric
// signal gets its turn. Outdoors the intensity keypoints barely repeat, and their best pose can explain 0.85
// of the evidence from a tenth of the scans in overlap, 34 m off, or 0.90 turned by 66 degrees.
constexpr double kFullySupportedWithFreeSpace = 0.95;
double well_supported(double overlap, bool free_space) {
  return free_space ? kWellSupportedWithFreeSpace : std::min(kSignalFallback, 0.75 * overlap);
}

// The automatic overlap: rounds of fresh bases, each for a smaller overlap (more and narrower bases),
// while no pose is well supported.
constexpr double kAutoOverlaps[] = {0.8, 0.6, 0.4};

// Whether two hypotheses nearly as well supported as the best (within the contender band) share a rotation
// (within 5 degrees) but put the source's centre (centre_m) more than min_shift_m apart: the scene repeats under
// a shift. In a symmetric room the rivals are turned copies of each other instead.
bool repeats_under_a_shift(const std::vector<Hypothesis>& hypotheses, const Eigen::Vector3d& centre_m,
                           double min_shift_m) {
  constexpr double kSameRotationDeg = 5.0;
  std::vector<const Eigen::Matrix4d*> leading;
  for (const Hypothesis& h : hypotheses)
    if (h.cloud_score >= (1.0 - kContenderBand) * hypotheses.front().cloud_score) leading.push_back(&h.transform);
  for (std::size_t i = 0; i < leading.size(); ++i)
    for (std::size_t j = i + 1; j < leading.size(); ++j) {
      const Eigen::Matrix4d &a = *leading[i], &b = *leading[j];
      const double angle_deg = rotation_angle_deg(a.topLeftCorner<3, 3>().transpose() * b.topLeftCorner<3, 3>());
      if (angle_deg < kSameRotationDeg && shift_at_m(a, b, centre_m) > min_shift_m) return true;
    }
  return false;
}

// The single-scale pipeline's outcome: the result, and whether its pose is well supported.
struct ScaleAttempt {
  RegistrationResult result;
  bool supported = false;
};

// The inverse of to_file_frames.
Eigen::Matrix4d to_local_frames(const Eigen::Matrix4d& file, const Eigen::Vector3d& source_origin,
                                const Eigen::Vector3d& target_origin) {
  Eigen::Matrix4d t = file;
  t.topRightCorner<3, 1>() -= target_origin - file.topLeftCorner<3, 3>() * source_origin;
  return t;
}

// The outcome of steps 2-4 at one scale: the chosen coarse alignment, the smallest overlap searched (what a true
// pose must explain) and the bases tried in all rounds.
struct CoarseOutcome {
  CoarseAlignment chosen;
  double overlap_searched = 0.0;
  int bases_tried = 0;
};

using PyramidPair = std::pair<const IcpPyramid&, const IcpPyramid&>;  // source, target

// The single-scale pipeline for one pair at minimum scale sigma, one named step per method: the voxel grid and
// the free space (on construction), then either the search (steps 2-4) or given poses judged in its place, then
// refinement and verdict (step 5). The steps share the voxels, ICP pyramids, free space and point sets.
class ScalePipeline {
 public:
  ScalePipeline(const PreparedScan& source, const PreparedScan& target, const RegistrationParams& params,
                double sigma, const CancellationToken* cancel, const ProgressCallback& progress)
      : source_scan_(source), target_scan_(target), params_(params), sigma_(sigma), cancel_(cancel),
        progress_(progress), stages_(result_.timings, progress) {
    result_.seed = params.seed;
    result_.source_points = source.cloud().size();
    result_.target_points = target.cloud().size();
    result_.min_scale_m_used = sigma;
    icp_params_.voxel_m = sigma;
    icp_params_.max_iterations = params.icp_max_iterations;
    icp_params_.levelled = params.levelled;
    voxelise();
    see_free_space();
  }
  ScalePipeline(const ScalePipeline&) = delete;
  ScalePipeline& operator=(const ScalePipeline&) = delete;

  // Steps 2-4: rounds of bases (with the overlap automatic, fresh ones for smaller overlaps while no pose is well
  // supported; with it given, wider ones while no congruent set is found), on the intensity signal first and the
  // geometric one where intensity poses are weak.
  CoarseOutcome search();
  // Given poses (files' frames) in place of steps 2-3: the symmetry guard ranks them.
  CoarseOutcome given(const std::vector<Eigen::Matrix4d>& poses);
  // Step 5: refinement, the verdict, and the result in the files' frames.
  ScaleAttempt refine(const CoarseOutcome& coarse);

 private:
  void voxelise();
  void see_free_space();
  const PyramidPair& icp_pyramids();
  const PointSets& sets_for(KeypointSignal signal);
  CoarseAlignment coarse(KeypointSignal signal, double overlap, std::uint64_t seed);
  std::vector<double> overlaps() const;
  void flag_ambiguity(const Verdict& verdict, double needed, const SurfaceBar& bar);
  void to_files_frames(const Eigen::Matrix4d& local, const CoarseAlignment& chosen);

  const PreparedScan &source_scan_, &target_scan_;
  const RegistrationParams& params_;
  const double sigma_;
  const CancellationToken* cancel_;
  const ProgressCallback& progress_;
  RegistrationResult result_;
  StageRunner stages_;
  IcpParams icp_params_;
  const VoxelizedCloud *source_voxels_ = nullptr, *target_voxels_ = nullptr;
  std::optional<PyramidPair> pyramids_;  // built when first needed
  bool plain_ = false;
  double delta_ = 0.0;  // the point precision every 4PCS tolerance derives from
  ScanViews views_;
  const ScanViews* seen_ = nullptr;   // what the guard and the scorer weigh: views_ where free space is used
  std::deque<PointSets> point_sets_;  // one per signal asked for so far (a deque: CoarseAlignment points into it)
};

// 1. Voxel grid at the minimum scale (paper Sec. 2.1), and the 4PCS precision. Repeated keypoints of two scans
//    lie within about 2 sigma of each other (measured on the simulated lab and the bunny); plain 4PCS works on a
//    coarser grid, whose spacing it is.
void ScalePipeline::voxelise() {
  const auto voxelised = stages_.run("voxel_grid", [&] {
    return std::make_pair(&source_scan_.voxels(sigma_, cancel_), &target_scan_.voxels(sigma_, cancel_));
  });
  source_voxels_ = voxelised.first;
  target_voxels_ = voxelised.second;
  result_.source_voxels = source_voxels_->cloud.size();
  result_.target_voxels = target_voxels_->cloud.size();
  check_geometry(source_voxels_->cloud.points, sigma_, "source");
  check_geometry(target_voxels_->cloud.points, sigma_, "target");
  plain_ = params_.method == CoarseMethod::kPlain4pcs;
  delta_ = !plain_ ? 2.0 * sigma_ : stages_.run("plain_grid", [&] {
    return params_.plain_voxel_m > 0 ? params_.plain_voxel_m : spacing_for_count(source_voxels_->cloud, 4 * sigma_, 2000);
  });
}

// Free space (free_space.h), seen from the scanners or along the cameras (free_space_from). Raw points fill every
// cell.
void ScalePipeline::see_free_space() {
  const double margin_m = 3.0 * delta_;
  const FreeSpaceFrom from = stages_.run("scanner_position", [&] {
    return free_space_from(params_.free_space, source_scan_, target_scan_, sigma_, cancel_);
  });
  if (from == FreeSpaceFrom::kScanners)
    views_ = {&target_scan_.free_space(margin_m), Viewpoint::at(source_scan_.scanner_local(cancel_)),
              Viewpoint::at(target_scan_.scanner_local(cancel_))};
  if (from == FreeSpaceFrom::kCameras)
    views_ = {&target_scan_.view_free_space(sigma_, margin_m, cancel_),
              Viewpoint::along(*source_scan_.view_direction(sigma_, cancel_)),
              Viewpoint::along(*target_scan_.view_direction(sigma_, cancel_))};
  result_.source_scanner = source_scan_.scanner_known(cancel_);
  result_.target_scanner = target_scan_.scanner_known(cancel_);
  result_.free_space_used = views_.target_free_space != nullptr;
  seen_ = result_.free_space_used ? &views_ : nullptr;
}

// The ICP pyramids serve the symmetry guard and the final refinement.
const PyramidPair& ScalePipeline::icp_pyramids() {
  if (!pyramids_)
    pyramids_.emplace(stages_.run("icp_setup", [&] {
      return PyramidPair(source_scan_.pyramid(sigma_, icp_params_, PyramidRole::kSource, cancel_),
                         target_scan_.pyramid(sigma_, icp_params_, PyramidRole::kTarget, cancel_));
    }));
  return *pyramids_;
}

// 2. The point sets 4PCS runs on: DoG keypoints (K-4PCS) or a coarser voxel grid (plain 4PCS).
const PointSets& ScalePipeline::sets_for(KeypointSignal signal) {
  const bool intensity = source_scan_.cloud().has_intensity() && target_scan_.cloud().has_intensity();
  for (const PointSets& sets : point_sets_)
    if (sets.signal == (plain_ ? "voxels" : surface_signal_name(signal, intensity))) return sets;
  PointSets& sets = point_sets_.emplace_back();
  if (!plain_) {
    stages_.run("keypoints", [&] {
      const DogParams dog{sigma_, params_.octaves, params_.scales_per_octave, params_.min_contrast};
      const ScanKeypoints& from = source_scan_.keypoints(sigma_, signal, intensity, dog, cancel_);
      const ScanKeypoints& to = target_scan_.keypoints(sigma_, signal, intensity, dog, cancel_);
      sets.signal = to.signal;
      sets.source = from.points, sets.source_labels = from.labels;
      sets.target = to.points, sets.target_labels = to.labels;
      return 0;
    });
  } else {
    stages_.run("plain_grid", [&] {
      sets.source = voxel_grid(source_voxels_->cloud, delta_, cancel_).cloud.points;
      sets.target = voxel_grid(target_voxels_->cloud, delta_, cancel_).cloud.points;
      return 0;
    });
    sets.signal = "voxels";
  }
  return sets;
}

// 2-4. Coarse alignment on one signal with one round of bases: 4PCS, then the symmetry guard.
CoarseAlignment ScalePipeline::coarse(KeypointSignal signal, double overlap, std::uint64_t seed) {
  const PointSets& sets = sets_for(signal);
  constexpr std::size_t kMinKeypoints = 8;
  if (!plain_ && (sets.source.size() < kMinKeypoints || sets.target.size() < kMinKeypoints))
    fail(ErrorCode::kFailedPrecondition,
         "too few keypoints (source " + std::to_string(sets.source.size()) + ", target " +
             std::to_string(sets.target.size()) + ")");
  CoarseAlignment out;
  out.signal = sets.signal;
  out.source_keypoints = sets.source.size();
  out.target_keypoints = sets.target.size();
  out.source_points = &sets.source;
  out.target_points = &sets.target;
  out.overlap = overlap;

  // 3. 4PCS on the two point sets (paper Sec. 2.2).
  const FourPcsResult matched = stages_.run("matching", [&] {
    FourPcsParams four{delta_, overlap, params_.max_bases, params_.hypotheses_kept, seed};
    four.levelled = params_.levelled;
    if (!plain_) four.source_labels = &sets.source_labels, four.target_labels = &sets.target_labels;
    return match_4pcs(sets.source, sets.target, four, cancel_, progress_);
  });
  out.bases_tried = matched.bases_tried;

  // 4. Symmetry guard: settle each distinct hypothesis with a short coarse ICP and re-score it on the
  //    voxelised clouds, where the furniture that breaks a room's symmetry is visible.
  const PyramidPair& icp = icp_pyramids();
  out.guarded = stages_.run("symmetry_guard", [&] {
    return rank_hypotheses(icp.first, icp.second, matched.hypotheses,
                           {.overlap = overlap, .levelled = params_.levelled}, seen_, cancel_);
  });
  return out;
}

// The overlaps whose bases are searched, in turn: the automatic rounds, or the given overlap and then the wider
// automatic ones, narrowest first. A few keypoints (a small object) may form no base as narrow as the given
// overlap whose match repeats in the other scan; wider bases are the only others there are, and a pose they find
// must still explain the given overlap.
std::vector<double> ScalePipeline::overlaps() const {
  if (params_.overlap == 0.0) return {std::begin(kAutoOverlaps), std::end(kAutoOverlaps)};
  std::vector<double> rounds{params_.overlap};
  for (auto wider = std::rbegin(kAutoOverlaps); wider != std::rend(kAutoOverlaps); ++wider)
    if (*wider > params_.overlap) rounds.push_back(*wider);
  return rounds;
}

// Intensity first, as in the paper. Where its keypoints do not repeat between the scans (dark, noisy returns at
// grazing incidence outdoors, or a constant intensity field), the best pose it finds explains the clouds poorly or
// none is found at all; then the geometric signal gets its turn, and the pose the clouds support better stands
// (the cloud score does not depend on the signal).
CoarseOutcome ScalePipeline::search() {
  const bool may_fall_back = !plain_ && params_.signal == KeypointSignal::kAuto &&
                             source_scan_.cloud().has_intensity() && target_scan_.cloud().has_intensity();
  const std::vector<double> rounds = overlaps();
  std::optional<CoarseAlignment> chosen;
  std::optional<Error> failure;
  CoarseOutcome out;
  out.overlap_searched = rounds.front();
  for (std::size_t round = 0; round < rounds.size(); ++round) {
    out.overlap_searched = std::min(out.overlap_searched, rounds[round]);
    // Round 0 keeps the caller's seed; later rounds draw fresh bases.
    const std::uint64_t seed = params_.seed + 0x9E3779B97F4A7C15ULL * round;
    auto attempt = [&](KeypointSignal signal) {
      try {
        CoarseAlignment candidate = coarse(signal, rounds[round], seed);
        out.bases_tried += candidate.bases_tried;
        if (!chosen || candidate.best().cloud_score > chosen->best().cloud_score) chosen = std::move(candidate);
      } catch (const Error& e) {
        if (e.code() != ErrorCode::kFailedPrecondition) throw;
        if (!failure) failure = e;
      }
    };
    attempt(params_.signal);
    const double fallback = result_.free_space_used ? kFullySupportedWithFreeSpace : kSignalFallback;
    if (may_fall_back && (!chosen || chosen->best().cloud_score < fallback)) attempt(KeypointSignal::kGeometric);
    // Given the overlap, wider bases only while none has found a congruent set.
    if (chosen && (params_.overlap != 0.0 ||
                   chosen->best().cloud_score >= well_supported(rounds[round], result_.free_space_used)))
      break;
  }
  if (!chosen) throw *failure;
  out.chosen = std::move(*chosen);
  return out;
}

CoarseOutcome ScalePipeline::given(const std::vector<Eigen::Matrix4d>& poses) {
  CoarseOutcome out;
  out.overlap_searched = overlaps().front();
  CoarseAlignment& judged = out.chosen;
  judged.signal = "given";
  judged.overlap = out.overlap_searched;
  std::vector<Hypothesis> hypotheses(poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i)
    hypotheses[i].transform = to_local_frames(poses[i], source_scan_.cloud().origin_m, target_scan_.cloud().origin_m);
  const PyramidPair& icp = icp_pyramids();
  judged.guarded = stages_.run("symmetry_guard", [&] {
    return rank_hypotheses(icp.first, icp.second, std::move(hypotheses),
                           {.overlap = judged.overlap, .levelled = params_.levelled}, seen_, cancel_);
  });
  return out;
}

// 5. ICP refinement on the voxelised clouds (or just the quality figures with --no-icp). Where runner-ups come
//    close, each is refined fully and judged on what symmetry does not copy; every refined pose is scored again
//    (pose_score.h).
ScaleAttempt ScalePipeline::refine(const CoarseOutcome& coarse) {
  const CoarseAlignment& chosen = coarse.chosen;
  result_.signal = chosen.signal;
  result_.source_keypoints = chosen.source_keypoints;
  result_.target_keypoints = chosen.target_keypoints;
  result_.bases_tried = coarse.bases_tried;
  result_.overlap_used = chosen.overlap;

  const PyramidPair& icp = icp_pyramids();
  IcpParams final_params = icp_params_;
  if (!params_.icp) final_params.max_iterations = 0;  // quality figures only, at the finest stage
  const PoseScorer scorer(icp.first, icp.second, seen_, result_.overlap_used);
  const SurfaceBar bar(target_scan_, sigma_, cancel_);
  const ContenderJudging judging{icp.first, icp.second, scorer, bar, final_params, params_.icp, sigma_};
  auto judge = [&](const SymmetryGuardResult& guarded) { return judge_contenders(guarded, judging, stages_, cancel_); };
  Verdict verdict = judge(chosen.guarded);
  // Where the verdict cannot decide and the hypotheses show the scene repeating under a shift (a corridor's
  // doors every few metres), the truth may be a shifted copy that 4PCS did not find: the guard searches
  // wider, from the verdict's winner, and the verdict judges again. Only such pairs pay for it.
  if (params_.icp && (verdict.margin < kAmbiguousMargin || verdict.disputed_by > 0.0) &&
      repeats_under_a_shift(verdict.hypotheses, centroid(icp.first.stages.front().points),
                            2.0 * icp.second.stages.front().voxel_m)) {
    const SymmetryGuardResult wider = stages_.run("symmetry_guard", [&] {
      return rank_hypotheses(icp.first, icp.second, verdict.hypotheses,
                             {.overlap = result_.overlap_used, .levelled = params_.levelled, .periodic = true}, seen_,
                             cancel_);
    });
    verdict = judge(wider);
  }
  result_.hypotheses = std::move(verdict.hypotheses);
  result_.ambiguity_margin = verdict.margin;
  // The winner polished on every source point at the finest stage, and below it where that is cheap
  // (fine_polish.h); with --no-icp, its quality figures only.
  const Hypothesis& best = result_.hypotheses.front();
  const IcpResult final_icp = stages_.run("polish", [&] {
    return polish_winner(source_scan_, target_scan_, icp.first, icp.second, sigma_, best.transform, final_params,
                         cancel_);
  });
  const Eigen::Matrix4d local = params_.icp ? final_icp.transform : best.transform;
  result_.icp_converged = params_.icp && final_icp.converged;
  result_.icp_iterations = params_.icp ? verdict.iterations + final_icp.iterations : 0;
  result_.rmse_m = final_icp.rmse_m;
  result_.overlap = final_icp.overlap;
  result_.inliers = final_icp.inliers;
  result_.constraint = normalized_constraint(final_icp.translation_information);

  // The smallest overlap searched sets what a true pose must explain.
  const double needed = well_supported(coarse.overlap_searched, result_.free_space_used);
  flag_ambiguity(verdict, needed, bar);
  result_.well_supported = verdict.on_surface && best.refined_score >= needed;
  to_files_frames(local, chosen);
  const bool supported = result_.well_supported;
  return {std::move(result_), supported};
}

// Whether the result is flagged ambiguous, and why, in words.
void ScalePipeline::flag_ambiguity(const Verdict& verdict, double needed, const SurfaceBar& bar) {
  const Hypothesis& best = result_.hypotheses.front();
  if (!verdict.on_surface) {
    result_.ambiguous = true;
    result_.ambiguity_reason = fmt::format(
        "off the surface: once refined, {:.0f} % of the source points near the target lie on its surface (true "
        "poses: {:.0f} % or more)",
        100 * best.surface_agreement, 100 * bar.required());
  } else if (best.refined_score < needed) {
    result_.ambiguous = true;
    result_.ambiguity_reason = fmt::format(
        "poorly supported: the best pose explains {:.0f} % of the source once refined (true poses: {:.0f} % or more)",
        100 * best.refined_score, 100 * needed);
  } else if (result_.hypotheses.size() >= 2 && result_.ambiguity_margin < ambiguous_below(result_.free_space_used)) {
    result_.ambiguous = true;
    result_.ambiguity_reason = fmt::format(
        "a runner-up pose is nearly as well supported (margin {:.3f} < {}{}): the scene may be symmetric; see the "
        "hypotheses",
        result_.ambiguity_margin, ambiguous_below(result_.free_space_used),
        result_.free_space_used ? "" : ", judged on geometry alone");
  } else if (verdict.disputed_by > 0.0) {
    result_.ambiguous = true;
    result_.ambiguity_reason = fmt::format(
        "the evidence disagrees: the best supported pose lies {:.0f} % on the target surface, a runner-up nearly as "
        "well supported {:.0f} %: the scene may repeat; see the hypotheses",
        100 * best.surface_agreement, 100 * verdict.disputed_by);
  }
}

// The pose, the hypotheses, their bases and the keypoints 4PCS matched, in the files' frames.
void ScalePipeline::to_files_frames(const Eigen::Matrix4d& local, const CoarseAlignment& chosen) {
  const Eigen::Vector3d &source_origin = source_scan_.cloud().origin_m, &target_origin = target_scan_.cloud().origin_m;
  result_.transform = to_file_frames(local, source_origin, target_origin);
  auto in_file_frame = [](std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& origin) {
    for (Eigen::Vector3d& p : points) p += origin;
  };
  for (Hypothesis& h : result_.hypotheses) {
    h.transform = to_file_frames(h.transform, source_origin, target_origin);
    in_file_frame(h.base_source_m, source_origin);
    in_file_frame(h.base_target_m, target_origin);
  }
  if (chosen.source_points)
    for (const Eigen::Vector3f& p : *chosen.source_points)
      result_.source_keypoint_positions_m.push_back(p.cast<double>() + source_origin);
  if (chosen.target_points)
    for (const Eigen::Vector3f& p : *chosen.target_points)
      result_.target_keypoint_positions_m.push_back(p.cast<double>() + target_origin);
}

// The single-scale pipeline, steps 1-5: the pair searched at minimum scale sigma.
ScaleAttempt register_at_scale(const PreparedScan& source, const PreparedScan& target, const RegistrationParams& params,
                               double sigma, const CancellationToken* cancel, const ProgressCallback& progress) {
  ScalePipeline pipeline(source, target, params, sigma, cancel, progress);
  return pipeline.refine(pipeline.search());
}

// Given poses (files' frames) judged at minimum scale sigma: the symmetry guard and the verdict rank them instead
// of what 4PCS would find.
ScaleAttempt judge_at_scale(const PreparedScan& source, const PreparedScan& target, const RegistrationParams& params,
                            double sigma, const std::vector<Eigen::Matrix4d>& poses, const CancellationToken* cancel,
                            const ProgressCallback& progress) {
  ScalePipeline pipeline(source, target, params, sigma, cancel, progress);
  return pipeline.refine(pipeline.given(poses));
}

// The start: DoG scales run from sigma to 2^5 sigma, and at diameter / 128 the coarsest octave still sees a
// quarter of the scene, so a scan of any size and unit yields keypoints at every octave. No coarser than 10
// point spacings, though (a voxel then averages ~100 points): a large outdoor scene, dense near the scanner,
// would otherwise start at a scale that only its far field needs.
constexpr double kDiameterPerScale = 128.0;
constexpr double kSpacingsPerScale = 10.0;

// The scales to try, coarsest first: the caller's or the automatic start, halved while a scale finds
// too few keypoints or no well-supported pose, down to the point spacing.
class ScaleLadder {
 public:
  ScaleLadder(const PreparedScan& source, const PreparedScan& target, double min_scale_m)
      : source_(source), target_(target), start_m_(starting_scale_m(source, target, min_scale_m)) {}
  double start_m() const { return start_m_; }
  // The scale after `scale_m`, or 0 when none is left.
  double next(double scale_m, int tried) {
    if (tried >= kMaxScales) return 0.0;
    const double spacing_m = std::max(source_.sampling().spacing_m, target_.sampling().spacing_m);
    return 0.5 * scale_m >= spacing_m ? 0.5 * scale_m : 0.0;
  }

 private:
  static constexpr int kMaxScales = 4;
  const PreparedScan& source_;
  const PreparedScan& target_;
  double start_m_;
};

// Where a scale finds no well-supported pose: the search from the other side. 4PCS draws its bases in the
// source, and one scan's keypoints may be ones its partner does not repeat while the partner's are found in it
// (the bunny at 3 mm: bun270 -> bun000 ends turned by 161 deg in two seeds of three, bun000 -> bun270 right in
// all three). A well-supported pose found from there is judged again from this side, among this side's
// hypotheses, so that the result keeps its source -> target figures and its margin; it stands if it is well
// supported from this side too. Stage times are added to `timings`.
std::optional<ScaleAttempt> from_the_other_side(const PreparedScan& source, const PreparedScan& target,
                                                const RegistrationParams& params, double sigma,
                                                const RegistrationResult& forward, std::vector<StageTiming>& timings,
                                                const CancellationToken* cancel, const ProgressCallback& progress) {
  std::optional<ScaleAttempt> swapped;
  try {
    swapped = register_at_scale(target, source, params, sigma, cancel, progress);
  } catch (const Error& e) {
    if (e.code() != ErrorCode::kFailedPrecondition) throw;
    return std::nullopt;
  }
  add_timings(timings, swapped->result.timings);
  if (!swapped->supported) return std::nullopt;
  const RegistrationResult& found = swapped->result;
  std::vector<Eigen::Matrix4d> poses{found.transform.inverse()};
  for (const Hypothesis& h : forward.hypotheses) poses.push_back(h.transform);
  RegistrationParams judging = params;
  judging.overlap = found.overlap_used;
  ScaleAttempt judged = judge_at_scale(source, target, judging, sigma, poses, cancel, progress);
  add_timings(timings, judged.result.timings);
  if (!judged.supported) return std::nullopt;
  // What found the pose, told from this side.
  RegistrationResult& r = judged.result;
  r.signal = found.signal;
  r.source_keypoints = found.target_keypoints;
  r.target_keypoints = found.source_keypoints;
  r.source_keypoint_positions_m = found.target_keypoint_positions_m;
  r.target_keypoint_positions_m = found.source_keypoint_positions_m;
  r.bases_tried = forward.bases_tried + found.bases_tried;
  return judged;
}

RegistrationResult run(const PreparedScan& source, const PreparedScan& target, const RegistrationParams& params,
                       const CancellationToken* cancel, const ProgressCallback& progress) {
  ScaleLadder ladder(source, target, params.min_scale_m);
  std::optional<RegistrationResult> best;
  std::optional<Error> failure;
  std::vector<StageTiming> timings;
  int tried = 0;
  for (double sigma = ladder.start_m(); sigma > 0.0; sigma = ladder.next(sigma, tried)) {
    ++tried;
    try {
      ScaleAttempt attempt = register_at_scale(source, target, params, sigma, cancel, progress);
      add_timings(timings, attempt.result.timings);
      if (!attempt.supported && params.search_other_side)
        if (std::optional<ScaleAttempt> other =
                from_the_other_side(source, target, params, sigma, attempt.result, timings, cancel, progress))
          attempt = std::move(*other);
      // The first well-supported pose stands; failing one, the best supported of all scales tried.
      const double support = attempt.result.hypotheses.front().refined_score;
      if (attempt.supported || !best || support > best->hypotheses.front().refined_score) best = std::move(attempt.result);
      if (attempt.supported) break;
    } catch (const Error& e) {
      if (e.code() != ErrorCode::kFailedPrecondition) throw;
      if (!failure) failure = e;
    }
  }
  if (!best)
    fail(ErrorCode::kFailedPrecondition,
         std::string(failure->what()) + " at every scale tried from " + std::to_string(ladder.start_m()) +
             " m down to the point spacing: check that the clouds overlap");
  best->timings = std::move(timings);
  return std::move(*best);
}

}  // namespace

double starting_scale_m(const PreparedScan& source, const PreparedScan& target, double min_scale_m) {
  if (min_scale_m > 0.0) return min_scale_m;
  const Sampling &s = source.sampling(), &t = target.sampling();
  const double spacing_m = std::max(s.spacing_m, t.spacing_m);
  const double coarsest = std::min(s.diameter_m, t.diameter_m) / kDiameterPerScale;
  const double start_m = std::max(std::min(coarsest, kSpacingsPerScale * spacing_m), 2.0 * spacing_m);
  if (!(start_m > 0.0)) fail(ErrorCode::kInvalidArgument, "the clouds have no extent: all points coincide");
  return start_m;
}

RegistrationResult register_clouds(const PointCloud& source, const PointCloud& target, const RegistrationParams& params,
                                   const CancellationToken* cancel, const ProgressCallback& progress) {
  return register_clouds(PreparedScan(source), PreparedScan(target), params, cancel, progress);
}

RegistrationResult judge_poses(const PreparedScan& source, const PreparedScan& target, const RegistrationParams& params,
                               const std::vector<Eigen::Matrix4d>& poses, const CancellationToken* cancel) {
  validate(params);
  if (params.overlap == 0.0) fail(ErrorCode::kInvalidArgument, "judging given poses needs the overlap they were found at");
  if (poses.empty()) fail(ErrorCode::kInvalidArgument, "no poses to judge");
  if (source.cloud().empty() || target.cloud().empty()) fail(ErrorCode::kInvalidArgument, "a cloud is empty");
  tbb::task_arena arena(params.threads > 0 ? params.threads : tbb::task_arena::automatic);
  RegistrationResult result;
  arena.execute([&] {
    const double sigma = ScaleLadder(source, target, params.min_scale_m).start_m();
    result = judge_at_scale(source, target, params, sigma, poses, cancel, {}).result;
  });
  return result;
}

RegistrationResult register_clouds(const PreparedScan& source, const PreparedScan& target,
                                   const RegistrationParams& params, const CancellationToken* cancel,
                                   const ProgressCallback& progress) {
  validate(params);
  if (source.cloud().empty()) fail(ErrorCode::kInvalidArgument, "source cloud is empty");
  if (target.cloud().empty()) fail(ErrorCode::kInvalidArgument, "target cloud is empty");
  // A time budget becomes a deadline on a private token that also follows the caller's cancellation.
  CancellationToken budget(cancel);
  if (params.time_budget_s > 0)
    budget.set_deadline(deadline_in(params.time_budget_s));
  tbb::task_arena arena(params.threads > 0 ? params.threads : tbb::task_arena::automatic);
  RegistrationResult result;
  arena.execute([&] { result = run(source, target, params, &budget, progress); });
  return result;
}

}  // namespace k4reg
