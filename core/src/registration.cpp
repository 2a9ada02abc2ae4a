#include "k4reg/registration.h"

#include <Eigen/Eigenvalues>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>

#include "k4reg/dog_keypoints.h"
#include "k4reg/error.h"
#include "k4reg/four_pcs.h"
#include "k4reg/free_space.h"
#include "k4reg/icp.h"
#include "k4reg/neighbor_grid.h"
#include "k4reg/rigid_fit.h"
#include "k4reg/surface_signal.h"
#include "k4reg/symmetry_guard.h"
#include "k4reg/voxel_grid.h"

namespace k4reg {
namespace {

using Clock = std::chrono::steady_clock;

class StageTimer {
 public:
  StageTimer(RegistrationResult& result, const ProgressCallback& progress) : result_(result), progress_(progress) {}
  template <typename F>
  auto run(const std::string& stage, F&& f) {
    if (progress_) progress_(stage, 0.0);
    const auto start = Clock::now();
    auto value = f();
    const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
    // A stage run twice (the geometric fallback) reports its total.
    auto same = std::find_if(result_.timings.begin(), result_.timings.end(),
                             [&](const StageTiming& t) { return t.stage == stage; });
    if (same != result_.timings.end())
      same->seconds += seconds;
    else
      result_.timings.push_back({stage, seconds});
    if (progress_) progress_(stage, 1.0);
    return value;
  }

 private:
  RegistrationResult& result_;
  const ProgressCallback& progress_;
};

}  // namespace

void validate(const RegistrationParams& p) {
  auto bad = [](const std::string& what) { fail(ErrorCode::kInvalidArgument, what); };
  if (!(p.min_scale_m >= 0.001 && p.min_scale_m <= 10.0)) bad("min_scale_m must be in [0.001, 10] m");
  if (!(p.overlap >= 0.05 && p.overlap <= 1.0)) bad("overlap must be in [0.05, 1]");
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

// The scanner sits at the file frame's origin, i.e. at -origin_m in the cloud's local frame.
Eigen::Vector3f scanner_position(const PointCloud& cloud) { return (-cloud.origin_m).cast<float>(); }

// Whether p lies inside the bounding box of the points.
bool inside_bounds(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& p) {
  Eigen::Vector3f low = Eigen::Vector3f::Constant(std::numeric_limits<float>::max()), high = -low;
  for (const Eigen::Vector3f& q : points) {
    low = low.cwiseMin(q);
    high = high.cwiseMax(q);
  }
  return (p.array() >= low.array()).all() && (p.array() <= high.array()).all();
}

bool use_free_space(FreeSpaceCheck check, const VoxelizedCloud& source, const VoxelizedCloud& target) {
  if (check != FreeSpaceCheck::kAuto) return check == FreeSpaceCheck::kOn;
  // A terrestrial scan in its scanner's frame surrounds the origin at metres. Object scans (whose origin
  // may sit inside the object) and georeferenced exports (whose origin is a map datum kilometres away)
  // say nothing about where the scanner stood.
  constexpr double kMinScannerRange_m = 1.0;
  auto scanner_known = [&](const PointCloud& cloud) {
    return inside_bounds(cloud.points, scanner_position(cloud)) &&
           FreeSpaceImage::median_range_m(cloud.points, scanner_position(cloud)) >= kMinScannerRange_m;
  };
  return scanner_known(source.cloud) && scanner_known(target.cloud);
}

// The voxel spacing at which a cloud keeps about `points` voxels (the paper's plain-4PCS baseline).
double spacing_for_count(const PointCloud& voxels, double start_m, std::size_t points) {
  double spacing = start_m;
  for (int step = 0; step < 40 && voxel_grid(voxels, spacing).cloud.size() > points; ++step) spacing *= 1.25;
  return spacing;
}

// The outcome of steps 2-4 for one keypoint signal.
struct CoarseAlignment {
  std::string signal;
  std::size_t source_keypoints = 0, target_keypoints = 0;
  int bases_tried = 0;
  SymmetryGuardResult guarded;
  const Hypothesis& best() const { return guarded.hypotheses.front(); }
};

// Source -> target in the files' frames from the transform between the local (origin-shifted) frames.
Eigen::Matrix4d to_file_frames(const Eigen::Matrix4d& local, const Eigen::Vector3d& source_origin,
                               const Eigen::Vector3d& target_origin) {
  Eigen::Matrix4d t = local;
  t.topRightCorner<3, 1>() += target_origin - local.topLeftCorner<3, 3>() * source_origin;
  return t;
}

RegistrationResult run(const PointCloud& source, const PointCloud& target, const RegistrationParams& params,
                       const CancellationToken* cancel, const ProgressCallback& progress) {
  RegistrationResult result;
  result.seed = params.seed;
  result.source_points = source.size();
  result.target_points = target.size();
  StageTimer timer(result, progress);
  const double sigma = params.min_scale_m;

  // 1. Voxel grid at the minimum scale (paper Sec. 2.1).
  // Named references rather than structured bindings: lambdas below use them, and clang < 16 cannot capture
  // a structured binding.
  const auto voxelised = timer.run("voxel_grid", [&] {
    return std::make_pair(voxel_grid(source, sigma, cancel), voxel_grid(target, sigma, cancel));
  });
  const VoxelizedCloud &source_voxels = voxelised.first, &target_voxels = voxelised.second;
  result.source_voxels = source_voxels.cloud.size();
  result.target_voxels = target_voxels.cloud.size();
  check_geometry(source_voxels.cloud.points, sigma, "source");
  check_geometry(target_voxels.cloud.points, sigma, "target");

  // The ICP pyramids serve the symmetry guard and the final refinement; built once, when first needed.
  IcpParams icp_params;
  icp_params.voxel_m = sigma;
  icp_params.max_iterations = params.icp_max_iterations;
  std::optional<std::pair<IcpPyramid, IcpPyramid>> pyramids;  // source, target
  auto icp_pyramids = [&]() -> const std::pair<IcpPyramid, IcpPyramid>& {
    if (!pyramids)
      pyramids = timer.run("icp_setup", [&] {
        return std::make_pair(make_icp_pyramid(source_voxels.cloud.points, icp_params, false, cancel),
                              make_icp_pyramid(target_voxels.cloud.points, icp_params, true, cancel));
      });
    return *pyramids;
  };
  // The point precision every 4PCS tolerance derives from. Repeated keypoints of two scans lie within
  // about 2 sigma of each other (measured on the simulated lab and the bunny); plain 4PCS works on a
  // coarser grid, whose spacing it is.
  const bool plain = params.method == CoarseMethod::kPlain4pcs;
  const double delta = !plain ? 2.0 * sigma : timer.run("plain_grid", [&] {
    return params.plain_voxel_m > 0 ? params.plain_voxel_m : spacing_for_count(source_voxels.cloud, 4 * sigma, 2000);
  });
  result.free_space_used = use_free_space(params.free_space, source_voxels, target_voxels);
  std::optional<FreeSpaceImage> free_space;
  if (result.free_space_used)
    free_space.emplace(target.points, scanner_position(target), 3.0 * delta);  // raw points fill every cell
  const ScanViews views{free_space ? &*free_space : nullptr, scanner_position(source), scanner_position(target)};

  // 2-4. Coarse alignment on one keypoint signal: the point sets, 4PCS, the symmetry guard.
  auto coarse = [&](KeypointSignal signal) {
    CoarseAlignment out;
    // 2. The point sets 4PCS runs on: DoG keypoints (K-4PCS) or a coarser voxel grid (plain 4PCS).
    std::vector<Eigen::Vector3f> source_set, target_set;
    std::vector<std::uint8_t> source_labels, target_labels;  // DoG extremum: 1 maximum, 0 minimum
    if (!plain) {
      timer.run("keypoints", [&] {
        const bool intensity = source.has_intensity() && target.has_intensity();
        DogParams dog{sigma, params.octaves, params.scales_per_octave, params.min_contrast};
        for (const auto* voxels : {&source_voxels, &target_voxels}) {
          const SurfaceSignal surface = make_surface_signal(voxels->cloud, sigma, signal, intensity, cancel);
          out.signal = surface.name;
          const bool is_source = voxels == &source_voxels;
          DogKeypoints keypoints = detect_dog_keypoints(voxels->cloud.points, surface.values, dog, cancel);
          auto& labels = is_source ? source_labels : target_labels;
          for (const float response : keypoints.response) labels.push_back(response > 0.0f);
          (is_source ? source_set : target_set) = std::move(keypoints.points);
        }
        return 0;
      });
      constexpr std::size_t kMinKeypoints = 8;
      if (source_set.size() < kMinKeypoints || target_set.size() < kMinKeypoints)
        fail(ErrorCode::kFailedPrecondition,
             "too few keypoints (source " + std::to_string(source_set.size()) + ", target " +
                 std::to_string(target_set.size()) + "): try a smaller min_scale_m or check the clouds");
    } else {
      timer.run("plain_grid", [&] {
        source_set = voxel_grid(source_voxels.cloud, delta, cancel).cloud.points;
        target_set = voxel_grid(target_voxels.cloud, delta, cancel).cloud.points;
        return 0;
      });
      out.signal = "voxels";
    }
    out.source_keypoints = source_set.size();
    out.target_keypoints = target_set.size();

    // 3. 4PCS on the two point sets (paper Sec. 2.2).
    const FourPcsResult matched = timer.run("matching", [&] {
      FourPcsParams four{delta, params.overlap, params.max_bases, params.hypotheses_kept, params.seed};
      if (!plain) four.source_labels = &source_labels, four.target_labels = &target_labels;
      return match_4pcs(source_set, target_set, four, cancel, progress);
    });
    out.bases_tried = matched.bases_tried;

    // 4. Symmetry guard: settle each distinct hypothesis with a short coarse ICP and re-score it on the
    //    voxelised clouds, where the furniture that breaks a room's symmetry is visible.
    const auto& icp = icp_pyramids();
    out.guarded = timer.run("symmetry_guard", [&] {
      return rank_hypotheses(icp.first, icp.second, matched.hypotheses, params.overlap, free_space ? &views : nullptr,
                             cancel);
    });
    return out;
  };

  // Intensity first, as in the paper. Where its keypoints do not repeat between the scans (dark, noisy
  // returns at grazing incidence outdoors, or a constant intensity field), the best pose it finds
  // explains the clouds poorly or none is found at all; then the geometric signal gets its turn, and
  // the pose the clouds support better stands (the cloud score does not depend on the signal).
  constexpr double kWellSupported = 0.6;  // cloud score of true poses: lab ~0.95, outdoor ~0.85
  std::optional<CoarseAlignment> chosen;
  const bool may_fall_back =
      !plain && params.signal == KeypointSignal::kAuto && source.has_intensity() && target.has_intensity();
  try {
    chosen = coarse(params.signal);
  } catch (const Error& e) {
    if (!may_fall_back || e.code() != ErrorCode::kFailedPrecondition) throw;
  }
  if (may_fall_back && (!chosen || chosen->best().cloud_score < kWellSupported)) {
    CoarseAlignment geometric = coarse(KeypointSignal::kGeometric);
    if (!chosen || geometric.best().cloud_score > chosen->best().cloud_score) chosen = std::move(geometric);
  }
  result.signal = chosen->signal;
  result.source_keypoints = chosen->source_keypoints;
  result.target_keypoints = chosen->target_keypoints;
  result.bases_tried = chosen->bases_tried;
  result.hypotheses = chosen->guarded.hypotheses;
  result.ambiguity_margin = chosen->guarded.ambiguity_margin;
  const Hypothesis& best = result.hypotheses.front();

  // 5. ICP refinement on the voxelised clouds (or just the quality figures with --no-icp).
  const IcpResult refined = timer.run("icp", [&] {
    IcpParams final_params = icp_params;
    if (!params.icp) final_params.max_iterations = 0;  // quality figures only, at the finest stage
    return refine_icp(icp_pyramids().first, icp_pyramids().second, best.transform, final_params, cancel);
  });
  const Eigen::Matrix4d local = params.icp ? refined.transform : best.transform;
  result.icp_converged = params.icp && refined.converged;
  result.icp_iterations = params.icp ? refined.iterations : 0;
  result.rmse_m = refined.rmse_m;
  result.overlap = refined.overlap;
  result.inliers = refined.inliers;

  result.transform = to_file_frames(local, source.origin_m, target.origin_m);
  for (Hypothesis& h : result.hypotheses) h.transform = to_file_frames(h.transform, source.origin_m, target.origin_m);
  return result;
}

}  // namespace

RegistrationResult register_clouds(const PointCloud& source, const PointCloud& target, const RegistrationParams& params,
                                   const CancellationToken* cancel, const ProgressCallback& progress) {
  validate(params);
  if (source.empty()) fail(ErrorCode::kInvalidArgument, "source cloud is empty");
  if (target.empty()) fail(ErrorCode::kInvalidArgument, "target cloud is empty");
  // A time budget becomes a deadline on a private token that also follows the caller's cancellation.
  CancellationToken budget(cancel);
  if (params.time_budget_s > 0)
    budget.set_deadline(Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(params.time_budget_s)));
  tbb::task_arena arena(params.threads > 0 ? params.threads : tbb::task_arena::automatic);
  RegistrationResult result;
  arena.execute([&] { result = run(source, target, params, &budget, progress); });
  return result;
}

}  // namespace k4reg
