// End-to-end K-4PCS on real scans with ground truth: the Stanford bunny (no intensity, so the
// geometric signal), survey-sized coordinates, determinism, cancellation and every error case.
#include "k4reg/registration/registration.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <future>
#include <random>
#include <thread>

#include "k4reg/io/cloud_io.h"
#include "k4reg/util/error.h"
#include "error_code_of.h"
#include "k4reg/io/gt_pairs.h"
#include "k4reg/registration/metrics.h"
#include "k4reg/registration/prepared_scan.h"

namespace k4reg {
namespace {

const std::string kBunny = std::string(K4REG_TEST_DATA_DIR) + "/bunny/";
constexpr double kBunnyScale_m = 0.001;   // the bunny is 0.15 m across, sampled every ~0.7 mm
constexpr double kBunnySuccess_m = 0.005; // true-correspondence RMSE: ~3 % of the object

GtPair bunny_pair(const std::string& source, const std::string& target) {
  for (const GtPair& p : read_gt_pairs(kBunny + "gt_pairs.log"))
    if (p.source == source && p.target == target) return p;
  throw std::runtime_error("no ground truth for " + source + " -> " + target);
}


RegistrationParams bunny_params(double overlap) {
  RegistrationParams p;
  p.min_scale_m = kBunnyScale_m;
  p.overlap = overlap;
  return p;
}

TEST(Registration, BunnyTenHighestOverlapPairs) {
  std::vector<GtPair> pairs = read_gt_pairs(kBunny + "gt_pairs.log");
  std::stable_sort(pairs.begin(), pairs.end(), [](const GtPair& a, const GtPair& b) { return a.overlap > b.overlap; });
  pairs.resize(10);
  int successes = 0;
  for (const GtPair& pair : pairs) {
    const PointCloud source = read_cloud(kBunny + pair.source), target = read_cloud(kBunny + pair.target);
    try {
      const RegistrationResult r = register_clouds(source, target, bunny_params(pair.overlap));
      const TransformError e = transform_error(source.points, r.transform, pair.T_target_source);
      EXPECT_EQ(r.signal, "geometric");
      successes += registration_succeeded(e, kBunnySuccess_m);
      std::printf("%-14s -> %-10s overlap %.2f  rotation error %7.3f deg  RMSE %.5f m  margin %.2f\n",
                  pair.source.c_str(), pair.target.c_str(), pair.overlap, e.rotation_deg, e.rmse_m, r.ambiguity_margin);
    } catch (const Error& e) {
      std::printf("%s -> %s: %s\n", pair.source.c_str(), pair.target.c_str(), e.what());
    }
  }
  EXPECT_GE(successes, 8);
}

// The poses a project's loops imply are judged as the pair's own hypotheses are: the true pose wins over a
// half-turned one, whichever is given first, and the result carries the same figures.
TEST(Registration, JudgedPosesPickTheTrueOneOnTheCloudsEvidence) {
  const GtPair pair = bunny_pair("bun045.ply", "bun000.ply");
  const PointCloud source = read_cloud(kBunny + pair.source), target = read_cloud(kBunny + pair.target);
  const PreparedScan from(source), to(target);
  Eigen::Matrix4d turned = Eigen::Matrix4d::Identity();
  turned.topLeftCorner<3, 3>() = Eigen::AngleAxisd(3.14159265, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Matrix4d wrong = pair.T_target_source * turned;
  // 2 degrees and 5 mm off: what a pose composed of two pairwise results may carry.
  Eigen::Matrix4d nudge = Eigen::Matrix4d::Identity();
  nudge.topLeftCorner<3, 3>() = Eigen::AngleAxisd(0.035, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  nudge(0, 3) = 0.005;
  const Eigen::Matrix4d near_truth = nudge * pair.T_target_source;
  const RegistrationParams params = bunny_params(0.9);
  for (const std::vector<Eigen::Matrix4d>& poses : {std::vector{wrong, near_truth}, std::vector{near_truth, wrong}}) {
    const RegistrationResult r = judge_poses(from, to, params, poses);
    const TransformError e = transform_error(source.points, r.transform, pair.T_target_source);
    EXPECT_LT(e.rmse_m, 0.001);
    EXPECT_TRUE(r.well_supported);
    EXPECT_FALSE(r.ambiguous) << r.ambiguity_reason;
    EXPECT_GE(r.hypotheses.size(), 2u);
    EXPECT_DOUBLE_EQ(r.min_scale_m_used, params.min_scale_m);
    EXPECT_DOUBLE_EQ(r.overlap_used, params.overlap);
  }
  // An automatic scale is judged at the scale register_clouds starts from.
  RegistrationParams automatic = params;
  automatic.min_scale_m = 0.0;
  const RegistrationResult judged = judge_poses(from, to, automatic, {wrong, near_truth});
  EXPECT_LT(transform_error(source.points, judged.transform, pair.T_target_source).rmse_m, 0.001);
  EXPECT_DOUBLE_EQ(judged.min_scale_m_used, register_clouds(source, target, automatic).min_scale_m_used);
  RegistrationParams no_overlap = params;
  no_overlap.overlap = 0.0;
  EXPECT_EQ(test::error_code_of([&] { judge_poses(from, to, no_overlap, {wrong}); }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(test::error_code_of([&] { judge_poses(from, to, params, {}); }), ErrorCode::kInvalidArgument);
}

TEST(Registration, ResultCarriesTheEvidence) {
  const GtPair pair = bunny_pair("bun045.ply", "bun000.ply");
  const PointCloud source = read_cloud(kBunny + pair.source), target = read_cloud(kBunny + pair.target);
  RegistrationParams params = bunny_params(0.9);
  params.seed = 7;
  const RegistrationResult r = register_clouds(source, target, params);
  const TransformError e = transform_error(source.points, r.transform, pair.T_target_source);
  EXPECT_LT(e.rmse_m, 0.001);  // after ICP: well under the 0.7 mm sampling
  EXPECT_LT(r.rmse_m, 0.001);
  EXPECT_GT(r.overlap, 0.7);
  EXPECT_GT(r.inliers, 1000u);
  EXPECT_EQ(r.source_points, source.size());
  EXPECT_GT(r.source_keypoints, 20u);
  EXPECT_GT(r.target_keypoints, 20u);
  EXPECT_EQ(r.seed, 7u);
  EXPECT_FALSE(r.hypotheses.empty());
  EXPECT_GE(r.ambiguity_margin, 0.0);
  EXPECT_LE(r.ambiguity_margin, 1.0);
  std::vector<std::string> stages;
  for (const StageTiming& t : r.timings) stages.push_back(t.stage);
  EXPECT_EQ(stages, (std::vector<std::string>{"voxel_grid", "scanner_position", "keypoints", "matching", "icp_setup",
                                               "symmetry_guard", "icp", "verdict", "polish"}));

  params.icp = false;
  const RegistrationResult coarse = register_clouds(source, target, params);
  const TransformError ce = transform_error(source.points, coarse.transform, pair.T_target_source);
  EXPECT_LT(ce.rmse_m, kBunnySuccess_m);  // the coarse result alone is inside ICP's basin
  EXPECT_FALSE(coarse.icp_converged);
}

TEST(Registration, SameTransformForAnyThreadCount) {
  const GtPair pair = bunny_pair("bun045.ply", "bun000.ply");
  const PointCloud source = read_cloud(kBunny + pair.source), target = read_cloud(kBunny + pair.target);
  RegistrationParams params = bunny_params(0.9);
  params.threads = 1;
  const RegistrationResult one = register_clouds(source, target, params);
  params.threads = 2;
  const RegistrationResult two = register_clouds(source, target, params);
  params.threads = 3;  // more threads than cores
  const RegistrationResult three = register_clouds(source, target, params);
  EXPECT_EQ(one.transform, two.transform);  // bit-identical
  EXPECT_EQ(one.transform, three.transform);
  EXPECT_EQ(one.source_keypoints, two.source_keypoints);
}

TEST(Registration, TwoRegistrationsAtOnceInOneProcess) {
  const GtPair pair = bunny_pair("bun045.ply", "bun000.ply");
  const PointCloud source = read_cloud(kBunny + pair.source), target = read_cloud(kBunny + pair.target);
  const RegistrationParams params = bunny_params(0.9);
  const RegistrationResult alone = register_clouds(source, target, params);
  auto a = std::async(std::launch::async, [&] { return register_clouds(source, target, params); });
  auto b = std::async(std::launch::async, [&] { return register_clouds(source, target, params); });
  EXPECT_EQ(a.get().transform, alone.transform);
  EXPECT_EQ(b.get().transform, alone.transform);
}

TEST(Registration, SurveyCoordinatesRegisterAsPreciselyAsAtTheOrigin) {
  const GtPair pair = bunny_pair("bun045.ply", "bun000.ply");
  const PointCloud source = read_cloud(kBunny + pair.source), target = read_cloud(kBunny + pair.target);
  // Both scans moved to UTM-sized coordinates, as double precision files would hold them.
  const Eigen::Vector3d offset(512345.678, 5240123.456, 312.5);
  PointCloud far_source = source, far_target = target;
  far_source.origin_m += offset;
  far_target.origin_m += offset;
  const RegistrationResult near = register_clouds(source, target, bunny_params(0.9));
  const RegistrationResult far = register_clouds(far_source, far_target, bunny_params(0.9));
  // Truth in the far frames: shift back, apply, shift forward.
  Eigen::Matrix4d shift = Eigen::Matrix4d::Identity();
  shift.topRightCorner<3, 1>() = offset;
  const Eigen::Matrix4d far_truth = shift * pair.T_target_source * shift.inverse();
  EXPECT_LT((far.transform.topLeftCorner<3, 3>() - near.transform.topLeftCorner<3, 3>()).norm(), 1e-9);
  Eigen::Matrix4d local_shift = Eigen::Matrix4d::Identity();  // metrics on the source's local points
  local_shift.topRightCorner<3, 1>() = far_source.origin_m;
  const TransformError e = transform_error(far_source.points, far.transform * local_shift, far_truth * local_shift);
  const TransformError e0 = transform_error(source.points, near.transform, pair.T_target_source);
  EXPECT_NEAR(e.rmse_m, e0.rmse_m, 1e-6);
  EXPECT_LT(e.rmse_m, 0.001);
}

TEST(Registration, CancellationStopsWithin100ms) {
  const GtPair pair = bunny_pair("bun045.ply", "bun000.ply");
  const PointCloud source = read_cloud(kBunny + pair.source), target = read_cloud(kBunny + pair.target);
  RegistrationParams params = bunny_params(0.9);
  params.max_bases = 200000;  // minutes of work
  CancellationToken token;
  auto job = std::async(std::launch::async,
                        [&] { return test::error_code_of([&] { register_clouds(source, target, params, &token); }); });
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const auto cancelled_at = std::chrono::steady_clock::now();
  token.cancel();
  EXPECT_EQ(job.get(), ErrorCode::kCancelled);
  EXPECT_LT(std::chrono::steady_clock::now() - cancelled_at, std::chrono::milliseconds(100));
}

TEST(Registration, TimeBudgetGivesDeadlineExceeded) {
  const GtPair pair = bunny_pair("bun045.ply", "bun000.ply");
  const PointCloud source = read_cloud(kBunny + pair.source), target = read_cloud(kBunny + pair.target);
  RegistrationParams params = bunny_params(0.9);
  params.max_bases = 200000;
  params.time_budget_s = 0.3;
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(test::error_code_of([&] { register_clouds(source, target, params); }), ErrorCode::kDeadlineExceeded);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(400));
}

TEST(Registration, ProgressReportsEveryStage) {
  const PointCloud source = read_cloud(kBunny + "bun045.ply"), target = read_cloud(kBunny + "bun000.ply");
  std::vector<std::string> started;
  register_clouds(source, target, bunny_params(0.9), nullptr, [&](const std::string& stage, double fraction) {
    if (fraction == 0.0) started.push_back(stage);
  });
  EXPECT_EQ(started, (std::vector<std::string>{"voxel_grid", "scanner_position", "keypoints", "matching", "icp_setup",
                                               "symmetry_guard", "icp", "verdict", "polish"}));
}

PointCloud grid_cloud(int nx, int ny, int nz, float step) {
  PointCloud cloud;
  for (int x = 0; x < nx; ++x)
    for (int y = 0; y < ny; ++y)
      for (int z = 0; z < nz; ++z) cloud.points.emplace_back(x * step, y * step, z * step);
  return cloud;
}

TEST(Registration, ClearErrors) {
  const PointCloud bunny = read_cloud(kBunny + "bun000.ply");
  const RegistrationParams ok = bunny_params(0.9);
  EXPECT_EQ(test::error_code_of([&] { register_clouds(PointCloud{}, bunny, ok); }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(test::error_code_of([&] { register_clouds(bunny, PointCloud{}, ok); }), ErrorCode::kInvalidArgument);
  for (double scale : {-1.0, 1e-6, 100.0, double(NAN)}) {
    RegistrationParams p = ok;
    p.min_scale_m = scale;
    EXPECT_EQ(test::error_code_of([&] { register_clouds(bunny, bunny, p); }), ErrorCode::kInvalidArgument) << scale;
  }
  for (double overlap : {1.5, -0.2, double(NAN)}) {
    RegistrationParams p = ok;
    p.overlap = overlap;
    EXPECT_EQ(test::error_code_of([&] { register_clouds(bunny, bunny, p); }), ErrorCode::kInvalidArgument) << overlap;
  }
  // Degenerate geometry: a plane and a line.
  const PointCloud plane = grid_cloud(100, 100, 1, 0.01f), line = grid_cloud(1000, 1, 1, 0.01f);
  EXPECT_EQ(test::error_code_of([&] { register_clouds(plane, plane, bunny_params(0.9)); }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(test::error_code_of([&] { register_clouds(line, bunny, bunny_params(0.9)); }), ErrorCode::kInvalidArgument);
  // A featureless box: a few uniform voxels give no DoG extrema.
  const PointCloud box = grid_cloud(4, 4, 4, 0.01f);
  EXPECT_EQ(test::error_code_of([&] { register_clouds(box, bunny, bunny_params(0.9)); }), ErrorCode::kFailedPrecondition);
  // Intensity requested for clouds without it.
  RegistrationParams intensity = ok;
  intensity.signal = KeypointSignal::kIntensity;
  EXPECT_EQ(test::error_code_of([&] { register_clouds(bunny, bunny, intensity); }), ErrorCode::kInvalidArgument);
}

// 30 000 points uniform in a bunny-sized box: shares no structure with any scan.
PointCloud random_box(unsigned seed) {
  PointCloud noise;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-0.07f, 0.07f);
  for (int i = 0; i < 30000; ++i) noise.points.emplace_back(u(rng), u(rng), u(rng));
  return noise;
}

TEST(Registration, NoHypothesisIsFailedPrecondition) {
  // Keypoints exist, but a bunny scan and a random cloud share no congruent 4-point sets.
  const PointCloud bunny = read_cloud(kBunny + "bun000.ply");
  const PointCloud noise = random_box(1);
  RegistrationParams p = bunny_params(0.9);
  p.max_bases = 10;
  const ErrorCode code = test::error_code_of([&] { register_clouds(bunny, noise, p); });
  EXPECT_EQ(code, ErrorCode::kFailedPrecondition);
}

// 4PCS draws its bases in the source. bun315's keypoints at 3 mm are ones bun045 barely repeats: searched from
// bun315 alone, seed 1 ends turned by 173 deg (flagged); searched from bun045 the truth is found, and judged
// again from bun315's side it stands, as a source -> target result.
TEST(Registration, APairThatTheSourceSideMissesIsFoundFromTheTargetSide) {
  const GtPair pair = bunny_pair("bun315.ply", "bun045.ply");
  const PointCloud source = read_cloud(kBunny + pair.source), target = read_cloud(kBunny + pair.target);
  RegistrationParams p;
  p.min_scale_m = 0.003;
  p.overlap = 0.6;
  p.seed = 1;
  const RegistrationResult r = register_clouds(source, target, p);
  EXPECT_LT(transform_error(source.points, r.transform, pair.T_target_source).rmse_m, kBunnySuccess_m);
  EXPECT_TRUE(r.well_supported);
  EXPECT_EQ(r.source_points, source.size());
  EXPECT_EQ(r.min_scale_m_used, 0.003);
  EXPECT_GT(r.source_keypoints, 0u);
  EXPECT_EQ(r.source_keypoint_positions_m.size(), r.source_keypoints);
  // Judged among the source side's own hypotheses, its turned winner included.
  const auto turned = std::count_if(r.hypotheses.begin(), r.hypotheses.end(), [&](const Hypothesis& h) {
    return rotation_angle_deg(h.transform.topLeftCorner<3, 3>().transpose() * pair.T_target_source.topLeftCorner<3, 3>()) > 90.0;
  });
  EXPECT_GE(turned, 1);
  // From the source's side alone, the turned pose wins.
  p.search_other_side = false;
  const RegistrationResult one_sided = register_clouds(source, target, p);
  EXPECT_GT(transform_error(source.points, one_sided.transform, pair.T_target_source).rmse_m, kBunnySuccess_m);
}

// Many files carry an intensity field that says nothing (e.g. a constant): with the signal on auto, the
// intensity attempt finds no keypoints, and the geometric signal takes over. Asked for intensity
// explicitly, the registration fails instead of second-guessing.
TEST(Registration, AutoSignalFallsBackToGeometryWhereIntensityCarriesNothing) {
  const GtPair pair = bunny_pair("bun045.ply", "bun000.ply");
  PointCloud source = read_cloud(kBunny + pair.source), target = read_cloud(kBunny + pair.target);
  for (PointCloud* cloud : {&source, &target}) cloud->intensity.assign(cloud->size(), 0.5f);
  const RegistrationResult r = register_clouds(source, target, bunny_params(pair.overlap));
  EXPECT_EQ(r.signal, "geometric");
  EXPECT_LT(transform_error(source.points, r.transform, pair.T_target_source).rmse_m, kBunnySuccess_m);
  RegistrationParams intensity = bunny_params(pair.overlap);
  intensity.signal = KeypointSignal::kIntensity;
  EXPECT_EQ(test::error_code_of([&] { register_clouds(source, target, intensity); }), ErrorCode::kFailedPrecondition);
}

// With no minimum scale and no overlap given, both come from the scans: the result says which it used,
// and the same scans in millimetres give the same pose (the translation in millimetres).
TEST(Registration, AutomaticParametersFollowTheScansAndTheirUnits) {
  const GtPair pair = bunny_pair("bun045.ply", "bun000.ply");
  PointCloud source = read_cloud(kBunny + pair.source), target = read_cloud(kBunny + pair.target);
  const RegistrationResult r = register_clouds(source, target, RegistrationParams{});
  const TransformError e = transform_error(source.points, r.transform, pair.T_target_source);
  EXPECT_LT(e.rmse_m, kBunnySuccess_m);
  EXPECT_FALSE(r.ambiguous) << r.ambiguity_reason;
  EXPECT_GT(r.min_scale_m_used, 0.0002);  // between the point spacing and 1/100 of the object
  EXPECT_LT(r.min_scale_m_used, 0.002);
  EXPECT_GE(r.overlap_used, 0.4);
  EXPECT_LE(r.overlap_used, 0.8);
  for (PointCloud* cloud : {&source, &target})
    for (Eigen::Vector3f& p : cloud->points) p *= 1000.0f;
  const RegistrationResult mm = register_clouds(source, target, RegistrationParams{});
  EXPECT_NEAR(mm.min_scale_m_used, 1000.0 * r.min_scale_m_used, 1e-3 * mm.min_scale_m_used);
  EXPECT_EQ(mm.overlap_used, r.overlap_used);
  EXPECT_LT((mm.transform.topLeftCorner<3, 3>() - r.transform.topLeftCorner<3, 3>()).norm(), 1e-3);
  EXPECT_LT((mm.transform.topRightCorner<3, 1>() - 1000.0 * r.transform.topRightCorner<3, 1>()).norm(), 1.0);  // < 1 mm
}

// Scans that share nothing: every scale and overlap is tried, and the answer is a refusal or a flagged
// pose, never a confident one.
TEST(Registration, ScansThatShareNothingAreNeverConfident) {
  const PointCloud bunny = read_cloud(kBunny + "bun000.ply");
  const PointCloud noise = random_box(3);
  try {
    const RegistrationResult r = register_clouds(bunny, noise, RegistrationParams{});
    EXPECT_TRUE(r.ambiguous);
    EXPECT_FALSE(r.ambiguity_reason.empty());
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kFailedPrecondition) << e.what();
  }
}

TEST(Registration, PlainFourPcsBaselineIsSelectable) {
  const GtPair pair = bunny_pair("bun045.ply", "bun000.ply");
  const PointCloud source = read_cloud(kBunny + pair.source), target = read_cloud(kBunny + pair.target);
  RegistrationParams params = bunny_params(0.9);
  params.method = CoarseMethod::kPlain4pcs;
  params.plain_voxel_m = 0.012;
  params.max_bases = 8;  // the baseline is slow by nature (the paper's Tab. 3); a few bases suffice here
  const RegistrationResult r = register_clouds(source, target, params);
  EXPECT_EQ(r.signal, "voxels");
  EXPECT_GT(r.source_keypoints, 100u);  // the coarse grid's points
  const TransformError e = transform_error(source.points, r.transform, pair.T_target_source);
  EXPECT_LT(e.rmse_m, kBunnySuccess_m);
}

}  // namespace
}  // namespace k4reg
