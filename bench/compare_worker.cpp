// The worker side of the comparison: loads one pair, runs one method and reports errors against the
// ground truth, stage times and keypoint counts as one JSON object.
//
// Result fields: ok, error, read_s (file reading, not part of total_s), convert_s (handing the clouds to the
// other library, not part of total_s: copying into PCL clouds; for Open3D writing them to PLY files, Python's
// start-up with import open3d, reading the files back), total_s (from loaded clouds to the final transform;
// Open3D's as its script measured it), stages {name: s},
// source_keypoints, target_keypoints, capped (over the wall-time cap: a failure), coarse and final
// {mae_deg, mte_m, rotation_deg, translation_m, rmse_m} (coarse = before ICP; PCL's and Open3D's methods
// have no ICP, so they are equal), sift_overflow_octaves, voxel_grid_overflow. The keypoint jobs report seconds,
// source_keypoints, target_keypoints, repeatability, and truth_overlap / plain_voxel_m (ours) or sift_overflow_octaves
// (PCL). PCL's K-4PCS and SIFT runs also report sift_peak_rss_mb (of the process that computed the keypoints, see
// sift_cache.h) and, when SIFT was killed on that scan before, sift_timed_out. A worker prints
// "PROGRESS {...}" lines with facts known before a long stage, then one "RESULT {...}" line.
#include <sys/resource.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <exception>
#include <numbers>
#include <random>

#include "compare_job.h"
#include "fpfh_methods.h"
#include "k4reg/geometry/neighbor_grid.h"
#include "k4reg/geometry/voxel_grid.h"
#include "k4reg/io/cloud_io.h"
#include "k4reg/registration/dog_keypoints.h"
#include "k4reg/registration/four_pcs.h"
#include "k4reg/registration/metrics.h"
#include "k4reg/registration/registration.h"
#include "k4reg/registration/surface_signal.h"
#include "k4reg/util/error.h"
#include "k4reg/util/stopwatch.h"
#include "open3d_peer.h"
#include "pcl_methods.h"
#include "sift_cache.h"
#include "truth_error.h"

namespace k4reg::bench {

using nlohmann::json;

void to_json(json& j, const Job& job) {
  j = json{{"method", job.method},       {"source", job.source},       {"target", job.target},
           {"unit_scale", job.unit_scale}, {"max_range_m", job.max_range_m}, {"pose_seed", job.pose_seed},
           {"sigma_m", job.sigma_m},     {"overlap", job.overlap},     {"plain_voxel_m", job.plain_voxel_m},
           {"seed", job.seed},           {"max_bases", job.max_bases}, {"pcl_iterations", job.pcl_iterations},
           {"cap_s", job.cap_s},         {"memory_cap_mb", job.memory_cap_mb},
           {"sift_cache_dir", job.sift_cache_dir}};
  j["truth"] = std::vector<double>(job.truth.data(), job.truth.data() + 16);  // column-major
}

void from_json(const json& j, Job& job) {
  j.at("method").get_to(job.method);
  j.at("source").get_to(job.source);
  j.at("target").get_to(job.target);
  j.at("unit_scale").get_to(job.unit_scale);
  j.at("max_range_m").get_to(job.max_range_m);
  j.at("pose_seed").get_to(job.pose_seed);
  j.at("sigma_m").get_to(job.sigma_m);
  j.at("overlap").get_to(job.overlap);
  j.at("plain_voxel_m").get_to(job.plain_voxel_m);
  j.at("seed").get_to(job.seed);
  j.at("max_bases").get_to(job.max_bases);
  j.at("pcl_iterations").get_to(job.pcl_iterations);
  j.at("cap_s").get_to(job.cap_s);
  j.at("memory_cap_mb").get_to(job.memory_cap_mb);
  j.at("sift_cache_dir").get_to(job.sift_cache_dir);
  const auto truth = j.at("truth").get<std::vector<double>>();
  if (truth.size() != 16) throw std::runtime_error("job: truth needs 16 numbers");
  job.truth = Eigen::Map<const Eigen::Matrix4d>(truth.data());
}

namespace {

// Facts known before a long stage, printed at once so the orchestrator still has them if the run is killed.
void report_progress(const json& facts) {
  std::printf("PROGRESS %s\n", facts.dump().c_str());
  std::fflush(stdout);
}

// The cache key of a cloud exactly as load_pair makes it from `file`.
std::string scan_key(const std::string& file, const Job& job, std::uint64_t pose_seed) {
  char buffer[96];
  std::snprintf(buffer, sizeof buffer, "|scale=%.9g|range=%.9g|pose=%llu", job.unit_scale, job.max_range_m,
                static_cast<unsigned long long>(pose_seed));
  return file + buffer;
}

Eigen::Matrix4d translation(const Eigen::Vector3d& t) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topRightCorner<3, 1>() = t;
  return m;
}

// A transform between the clouds' local frames expressed between the files' frames.
Eigen::Matrix4d file_from_local(const Eigen::Matrix4d& local, const PointCloud& source, const PointCloud& target) {
  return translation(target.origin_m) * local * translation(-source.origin_m);
}

Eigen::Matrix4d local_from_file(const Eigen::Matrix4d& file, const PointCloud& source, const PointCloud& target) {
  return translation(-target.origin_m) * file * translation(source.origin_m);
}

struct LoadedPair {
  PointCloud source, target;
  Eigen::Matrix4d truth;  // file frames, after scaling and the pose perturbation
  double read_s = 0.0;
};

// Scales coordinates and drops no-return points; a cloud that needs neither is returned untouched.
PointCloud conditioned(PointCloud cloud, double unit_scale, double max_range_m) {
  if (unit_scale == 1.0 && max_range_m <= 0.0) return cloud;
  std::vector<Eigen::Vector3d> world;
  std::vector<float> intensity;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d p = (cloud.origin_m + cloud.points[i].cast<double>()) * unit_scale;
    if (max_range_m > 0.0 && p.norm() > max_range_m) continue;
    world.push_back(p);
    if (cloud.has_intensity()) intensity.push_back(cloud.intensity[i]);
  }
  return make_local_cloud(world, std::move(intensity), "conditioned cloud");
}

// A random rigid motion: rotation of 30-180 deg about a random axis, translation of half the cloud's size.
Eigen::Matrix4d random_pose(std::uint64_t seed, double size_m) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> angle_deg(30.0, 180.0);
  const Eigen::Vector3d axis = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
  const Eigen::Vector3d shift = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized() * 0.5 * size_m;
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
  pose.topLeftCorner<3, 3>() = Eigen::AngleAxisd(angle_deg(rng) * std::numbers::pi / 180.0, axis).toRotationMatrix();
  pose.topRightCorner<3, 1>() = shift;
  return pose;
}

double extent_m(const PointCloud& cloud) {
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::max()), hi = -lo;
  for (const auto& p : cloud.points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  return cloud.empty() ? 0.0 : double((hi - lo).norm());
}

PointCloud moved(const PointCloud& cloud, const Eigen::Matrix4d& pose) {
  std::vector<Eigen::Vector3d> world(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i)
    world[i] = (pose * (cloud.origin_m + cloud.points[i].cast<double>()).homogeneous()).head<3>();
  return make_local_cloud(world, cloud.intensity, "moved source");
}

LoadedPair load_pair(const Job& job) {
  LoadedPair pair;
  const auto start = SteadyClock::now();
  PointCloud source = read_cloud(job.source), target = read_cloud(job.target);
  pair.read_s = seconds_since(start);
  pair.source = conditioned(std::move(source), job.unit_scale, job.max_range_m);
  pair.target = conditioned(std::move(target), job.unit_scale, job.max_range_m);
  pair.truth = job.truth;
  pair.truth.topRightCorner<3, 1>() *= job.unit_scale;
  if (job.pose_seed != 0) {
    const Eigen::Matrix4d pose = random_pose(job.pose_seed, extent_m(pair.source));
    pair.source = moved(pair.source, pose);
    pair.truth = pair.truth * pose.inverse();
  }
  return pair;
}

json errors(const PointCloud& source, const Eigen::Matrix4d& estimate, const Eigen::Matrix4d& truth) {
  const TransformError e = file_frame_error(source, estimate, truth);
  return {{"mae_deg", e.mae_deg},
          {"mte_m", e.mte_m},
          {"rotation_deg", e.rotation_deg},
          {"translation_m", e.translation_m},
          {"rmse_m", e.rmse_m}};
}

json stage_times(const std::vector<StageTiming>& timings) {
  json stages = json::object();
  for (const StageTiming& t : timings) stages[t.stage] = t.seconds;
  return stages;
}

struct PairSift {
  SceneSift source, target;
  double seconds() const { return source.seconds + target.seconds; }
  double peak_rss_mb() const { return std::max(source.peak_rss_mb, target.peak_rss_mb); }
  int overflowed_octaves() const { return std::max(source.overflowed_octaves, target.overflowed_octaves); }
};

// PCL's SIFT keypoints of both scans, from the cache when an earlier job computed them (SIFT is
// deterministic). SIFT's VoxelGrid overflow is reported before SIFT starts: it explains a killed run.
PairSift pcl_sift(const Job& job, const LoadedPair& pair) {
  const SiftParams sift{job.sigma_m};
  const bool intensity = pair.source.has_intensity() && pair.target.has_intensity();
  int overflowed = 0;
  const auto report_overflow = [&](const PclCloud& cloud) {
    overflowed = std::max(overflowed, sift_overflowed_octaves(cloud, sift));
    report_progress({{"sift_overflow_octaves", overflowed}});
  };
  const SiftCache cache(job.sift_cache_dir);
  PairSift out;
  out.source = cache.keypoints(pair.source, scan_key(job.source, job, job.pose_seed), intensity, sift, job.cap_s,
                               report_overflow);
  out.target = cache.keypoints(pair.target, scan_key(job.target, job, 0), intensity, sift, job.cap_s, report_overflow);
  return out;
}

PclCloud::Ptr pcl_points(const std::vector<Eigen::Vector3f>& points) {
  PointCloud cloud;
  cloud.points = points;
  return to_pcl(cloud);
}

void run_ours(const Job& job, const LoadedPair& pair, json& out) {
  RegistrationParams params;
  params.min_scale_m = job.sigma_m;
  params.overlap = job.overlap;
  params.seed = job.seed;
  params.max_bases = job.max_bases;
  params.time_budget_s = job.cap_s;
  if (job.method == kOursPlain) {
    params.method = CoarseMethod::kPlain4pcs;
    params.plain_voxel_m = job.plain_voxel_m;
  }
  const auto start = SteadyClock::now();
  const RegistrationResult r = register_clouds(pair.source, pair.target, params);
  out["total_s"] = seconds_since(start);
  out["stages"] = stage_times(r.timings);
  out["source_keypoints"] = r.source_keypoints;
  out["target_keypoints"] = r.target_keypoints;
  // The best hypothesis after the symmetry guard is exactly what an icp=false run would return.
  out["coarse"] = errors(pair.source, r.hypotheses.front().transform, pair.truth);
  out["final"] = errors(pair.source, r.transform, pair.truth);
}

// The peers' threads: both cores, as k4reg's TBB uses them.
constexpr int kPeerThreads = 2;

PclAlignParams pcl_align_params(const Job& job, double delta_m) {
  return PclAlignParams{delta_m, job.overlap, job.pcl_iterations, job.cap_s, kPeerThreads};
}

// The end of a method without a refinement stage: T is the sum of its stages, and coarse = final.
void report_unrefined(const Job& job, const LoadedPair& pair, const Eigen::Matrix4d& local, const json& stages,
                      json& out) {
  double total = 0.0;
  for (const auto& [stage, seconds] : stages.items()) total += seconds.get<double>();
  out["stages"] = stages;
  out["total_s"] = total;
  out["capped"] = total > job.cap_s;
  const json e = errors(pair.source, file_from_local(local, pair.source, pair.target), pair.truth);
  out["coarse"] = e;
  out["final"] = e;
}

void run_pcl(const Job& job, const LoadedPair& pair, json& out) {
  json stages = json::object();
  PclCloud::Ptr source_set, target_set;
  double delta = job.sigma_m;
  if (job.method == kPclK4pcs) {
    const PairSift sift = pcl_sift(job, pair);
    out["sift_overflow_octaves"] = sift.overflowed_octaves();
    out["sift_peak_rss_mb"] = sift.peak_rss_mb();
    source_set = pcl_points(sift.source.points), target_set = pcl_points(sift.target.points);
    stages["keypoints"] = sift.seconds();
  } else {
    auto start = SteadyClock::now();
    const PclCloud::Ptr source = to_pcl(pair.source), target = to_pcl(pair.target);
    out["convert_s"] = seconds_since(start);
    delta = job.plain_voxel_m;
    start = SteadyClock::now();
    source_set = pcl_voxel_grid(source, delta), target_set = pcl_voxel_grid(target, delta);
    out["voxel_grid_overflow"] = pcl_voxel_grid_overflows(*source, delta) || pcl_voxel_grid_overflows(*target, delta);
    stages["plain_grid"] = seconds_since(start);
  }
  out["source_keypoints"] = source_set->size();
  out["target_keypoints"] = target_set->size();
  if (source_set->size() < 4 || target_set->size() < 4) fail(ErrorCode::kFailedPrecondition, "too few keypoints");

  const auto start = SteadyClock::now();
  const PclAlignParams params = pcl_align_params(job, delta);
  const Eigen::Matrix4d local = job.method == kPclK4pcs ? pcl_kfpcs(source_set, target_set, params)
                                                       : pcl_fpcs(source_set, target_set, params);
  stages["matching"] = seconds_since(start);
  report_unrefined(job, pair, local, stages, out);
}

// FPFH + SAC-IA: features on both sigma voxel grids, then SAC-IA seeded with the trial.
void run_sac_ia(const Job& job, const LoadedPair& pair, json& out) {
  auto start = SteadyClock::now();
  const PclCloud::Ptr source = to_pcl(pair.source), target = to_pcl(pair.target);
  out["convert_s"] = seconds_since(start);
  json stages = json::object();
  start = SteadyClock::now();
  const FpfhParams fpfh{.voxel_m = job.sigma_m, .threads = kPeerThreads};
  const FpfhCloud source_features = pcl_fpfh(source, fpfh), target_features = pcl_fpfh(target, fpfh);
  stages["features"] = seconds_since(start);
  out["voxel_grid_overflow"] = source_features.voxel_grid_overflow || target_features.voxel_grid_overflow;
  out["source_keypoints"] = source_features.points->size();
  out["target_keypoints"] = target_features.points->size();
  if (source_features.points->size() < 3 || target_features.points->size() < 3)
    fail(ErrorCode::kFailedPrecondition, "too few points with an FPFH descriptor");
  start = SteadyClock::now();
  const SacIaParams sac_ia{.voxel_m = job.sigma_m, .seed = static_cast<unsigned>(job.seed)};
  const Eigen::Matrix4d local = pcl_sac_ia(source_features, target_features, sac_ia);
  stages["matching"] = seconds_since(start);
  report_unrefined(job, pair, local, stages, out);
}

// Open3D's FPFH + RANSAC or FGR in a child process (open3d_peer.h). The child gets the cap plus half the
// orchestrator's slack, so it is killed here before the orchestrator kills this worker and would orphan it.
void run_open3d(const Job& job, const LoadedPair& pair, json& out) {
  const Open3dPair r = open3d_pair(pair.source.points, pair.target.points, job.method == kOpen3dFgr ? "fgr" : "ransac",
                                   job.sigma_m, job.seed, kPeerThreads, job.cap_s + 0.5 * kHardLimitSlack_s);
  if (r.timed_out) fail(ErrorCode::kDeadlineExceeded, "open3d_pair.py killed after the wall cap");
  out["convert_s"] = r.wall_s - r.seconds;
  out["source_keypoints"] = r.source_points;
  out["target_keypoints"] = r.target_points;
  report_unrefined(job, pair, r.transform, json(r.stages), out);
}

// ETH office: the clouds are keypoints already; only the 4PCS stage runs.
void run_match(const Job& job, const LoadedPair& pair, json& out) {
  const auto start = SteadyClock::now();
  Eigen::Matrix4d local;
  if (job.method == kOursMatch) {
    FourPcsParams params{job.sigma_m, job.overlap, job.max_bases};
    params.seed = job.seed;
    local = match_4pcs(pair.source.points, pair.target.points, params).hypotheses.front().transform;
  } else {
    local = pcl_kfpcs(to_pcl(pair.source), to_pcl(pair.target), pcl_align_params(job, job.sigma_m));
  }
  out["total_s"] = seconds_since(start);
  out["stages"] = json{{"matching", out["total_s"]}};
  out["capped"] = out["total_s"].get<double>() > job.cap_s;
  out["source_keypoints"] = pair.source.size();
  out["target_keypoints"] = pair.target.size();
  const json e = errors(pair.source, file_from_local(local, pair.source, pair.target), pair.truth);
  out["coarse"] = e;
  out["final"] = e;
}

// Our detector exactly as register_clouds runs it (core/src/registration/registration.cpp, steps 1 and 2).
std::vector<Eigen::Vector3f> our_keypoints(const PointCloud& cloud, bool use_intensity, double sigma_m) {
  const VoxelizedCloud voxels = voxel_grid(cloud, sigma_m);
  const RegistrationParams defaults;
  const SurfaceSignal signal = make_surface_signal(voxels.cloud, sigma_m, defaults.signal, use_intensity);
  const DogParams dog{sigma_m, defaults.octaves, defaults.scales_per_octave, defaults.min_contrast};
  return detect_dog_keypoints(voxels.cloud.points, signal.values, dog).points;
}

// Share of source keypoints with a target keypoint within radius_m once moved by the truth (local frames).
double repeatability(const std::vector<Eigen::Vector3f>& source, const std::vector<Eigen::Vector3f>& target,
                     const Eigen::Matrix4d& truth_local, double radius_m) {
  if (source.empty() || target.empty()) return 0.0;
  const NeighborGrid grid(target, radius_m);
  const Eigen::Affine3f t(truth_local.cast<float>());
  std::size_t hits = 0;
  for (const auto& p : source) hits += grid.any_within(t * p, static_cast<float>(radius_m));
  return double(hits) / source.size();
}

// The plain-4PCS grid spacing: as in the paper (and register_clouds' default), the spacing at which the
// voxelised source keeps about as many points as it has keypoints.
double plain_spacing(const PointCloud& source, double sigma_m, std::size_t keypoints) {
  const PointCloud voxels = voxel_grid(source, sigma_m).cloud;
  double spacing = 4.0 * sigma_m;
  for (int step = 0; step < 40 && voxel_grid(voxels, spacing).cloud.size() > keypoints; ++step) spacing *= 1.25;
  return spacing;
}

void run_keypoints(const Job& job, const LoadedPair& pair, json& out) {
  const double sigma = job.sigma_m;
  const bool intensity = pair.source.has_intensity() && pair.target.has_intensity();
  const Eigen::Matrix4d truth_local = local_from_file(pair.truth, pair.source, pair.target);
  std::vector<Eigen::Vector3f> source, target;
  if (job.method == kKeypointsOurs) {
    const auto start = SteadyClock::now();
    source = our_keypoints(pair.source, intensity, sigma);
    target = our_keypoints(pair.target, intensity, sigma);
    out["seconds"] = seconds_since(start);
  } else {
    const PairSift sift = pcl_sift(job, pair);
    source = sift.source.points, target = sift.target.points;
    out["seconds"] = sift.seconds();
    out["sift_overflow_octaves"] = sift.overflowed_octaves();
    out["sift_peak_rss_mb"] = sift.peak_rss_mb();
    out["sift_from_cache"] = sift.source.from_cache && sift.target.from_cache;
  }
  out["source_keypoints"] = source.size();
  out["target_keypoints"] = target.size();
  out["repeatability"] = repeatability(source, target, truth_local, 2.0 * sigma);
  if (job.method == kKeypointsOurs) {
    // A check of the ground truth (and the true overlap): the same measure on the sigma voxel grids.
    out["truth_overlap"] = repeatability(voxel_grid(pair.source, sigma).cloud.points,
                                         voxel_grid(pair.target, sigma).cloud.points, truth_local, 2.0 * sigma);
    const double spacing = plain_spacing(pair.source, sigma, std::max<std::size_t>(source.size(), 4));
    out["plain_voxel_m"] = spacing;
  }
}

}  // namespace

json run_job(const Job& job) {
  json out = {{"method", job.method}, {"ok", false}, {"capped", false}};
  try {
    const LoadedPair pair = load_pair(job);
    out["read_s"] = pair.read_s;
    if (job.method == kOursK4pcs || job.method == kOursPlain) run_ours(job, pair, out);
    else if (job.method == kPclK4pcs || job.method == kPclPlain) run_pcl(job, pair, out);
    else if (job.method == kPclSacIa)
      run_sac_ia(job, pair, out);
    else if (job.method == kOpen3dRansac || job.method == kOpen3dFgr)
      run_open3d(job, pair, out);
    else if (job.method == kOursMatch || job.method == kPclMatch) run_match(job, pair, out);
    else if (job.method == kKeypointsOurs || job.method == kKeypointsPcl) run_keypoints(job, pair, out);
    else throw std::runtime_error("unknown method " + job.method);
    out["ok"] = true;
  } catch (const Error& e) {
    out["error"] = std::string(to_string(e.code())) + ": " + e.what();
    out["capped"] = e.code() == ErrorCode::kDeadlineExceeded;
  } catch (const SiftTimedOutEarlier& e) {
    out["error"] = e.what();
    out["sift_timed_out"] = true;
  } catch (const std::bad_alloc&) {
    out["error"] = "out of memory (over the " + std::to_string(job.memory_cap_mb) + " MB cap)";
  } catch (const std::exception& e) {
    out["error"] = e.what();
  }
  return out;
}

void limit_memory(const Job& job) {
  const rlim_t bytes = static_cast<rlim_t>(job.memory_cap_mb) << 20;
  const rlimit limit{bytes, bytes};
  setrlimit(RLIMIT_AS, &limit);
  std::set_terminate([] {
    try {
      if (const std::exception_ptr e = std::current_exception()) std::rethrow_exception(e);
    } catch (const std::bad_alloc&) {
      std::printf("\n%s\n", kOutOfMemoryLine);
      std::fflush(stdout);
    } catch (...) {
    }
    std::abort();
  });
}

}  // namespace k4reg::bench
