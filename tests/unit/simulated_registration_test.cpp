// K-4PCS on simulated terrestrial scans with exact ground truth, over 10 seeds per pair (each seed
// re-simulates both scans and seeds the registration): the lab's opposite corners (the half-turn
// symmetric shell makes the 180-degree flip the main trap), stations at different heights, and the
// outdoor arch at about 40 % overlap. Success
// by the paper's thresholds; after ICP the RMSE against ground truth stays under 2 cm, and the coarse
// result alone is already well inside ICP's basin.
#include <gtest/gtest.h>

#include <string>

#include "k4reg/io/cloud_io.h"
#include "k4reg/registration/metrics.h"
#include "k4reg/registration/registration.h"
#include "pose_error.h"
#include "sim/scanner.h"

namespace k4reg {
namespace {

struct SimulatedPair {
  std::string scene;
  int source_station = 0, target_station = 0;
  std::size_t points = 0;
  double min_scale_m = 0.05;
  double overlap = 0.8;
  double success_rmse_m = kIndoorSuccessRmse_m;
};

std::string pair_name(const testing::TestParamInfo<SimulatedPair>& info) {
  return info.param.scene + std::to_string(info.param.source_station) + "to" + std::to_string(info.param.target_station);
}

class SimulatedRegistration : public testing::TestWithParam<SimulatedPair> {};

TEST_P(SimulatedRegistration, TenSeeds) {
  const SimulatedPair& pair = GetParam();
  const sim::Scene scene = sim::make_scene(pair.scene);
  constexpr int kSeeds = 10;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    sim::ScanParams scan;
    scan.points = pair.points;
    scan.seed = 100 * seed + pair.source_station;
    const sim::SimulatedScan source = sim::simulate_scan(scene, pair.source_station, scan);
    scan.seed = 100 * seed + pair.target_station;
    const sim::SimulatedScan target = sim::simulate_scan(scene, pair.target_station, scan);
    const Eigen::Matrix4d truth = target.scan_to_scene.inverse() * source.scan_to_scene;

    RegistrationParams params;
    params.min_scale_m = pair.min_scale_m;
    params.overlap = pair.overlap;
    params.seed = seed;
    const RegistrationResult result = register_clouds(source.cloud, target.cloud, params);

    const TransformError final_error = transform_error(source.cloud.points, result.transform, truth);
    EXPECT_TRUE(registration_succeeded(final_error, pair.success_rmse_m))
        << "rotation " << final_error.rotation_deg << " deg, translation " << final_error.translation_m << " m";
    EXPECT_LT(final_error.rmse_m, 0.02);
    // The coarse pose (4PCS and the symmetry guard's short settle, before the final ICP) is already
    // within a small fraction of the coarsest ICP stage's reach.
    const TransformError coarse = transform_error(source.cloud.points, result.hypotheses.front().transform, truth);
    EXPECT_LT(coarse.rotation_deg, 1.0);
    EXPECT_LT(coarse.translation_m, 0.1);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Lab, SimulatedRegistration,
    testing::Values(SimulatedPair{"lab", 0, 1, 250000},   // opposite corners of the symmetric room
                    SimulatedPair{"lab", 2, 3, 250000},   // 1.5 m and 2.5 m high
                    SimulatedPair{"lab", 3, 4, 250000}),  // mirrored stations at different heights
    pair_name);

// The outdoor plaza at the paper's overlap parameter of 0.4 (Tab. 4): stations on either side of the arch
// share one face of it and the tops of the trees and buildings; on points, ICP finds under a fifth of
// the source's voxels within reach of the target. Minimum scale 0.1 m, the largest of the paper's three.
INSTANTIATE_TEST_SUITE_P(
    Outdoor, SimulatedRegistration,
    testing::Values(SimulatedPair{"arch", 0, 1, 500000, 0.1, 0.4, kOutdoorSuccessRmse_m},   // south-west -> east
                    SimulatedPair{"arch", 2, 3, 500000, 0.1, 0.4, kOutdoorSuccessRmse_m}),  // north -> west
    pair_name);

// Stations 0 and 1 of a scene layout, the source simulated with `seed` and the target with seed + 1, and the
// true source -> target transform.
struct SimulatedScans {
  sim::SimulatedScan source, target;
  Eigen::Matrix4d truth;
};
SimulatedScans simulate_pair(const std::string& scene_name, int layout, std::size_t points, std::uint64_t seed,
                             int source_station = 0, int target_station = 1,
                             sim::ScanFrame frame = sim::ScanFrame::kScanner) {
  const sim::Scene scene = sim::make_scene(scene_name, layout);
  sim::ScanParams scan;
  scan.points = points;
  scan.seed = seed;
  scan.frame = frame;
  SimulatedScans out{sim::simulate_scan(scene, source_station, scan), {}, {}};
  scan.seed = seed + 1;
  out.target = sim::simulate_scan(scene, target_station, scan);
  out.truth = out.target.scan_to_scene.inverse() * out.source.scan_to_scene;
  return out;
}

// The monument from both sides (a tuning layout of the blind protocol): 4PCS finds the half-turn flip,
// whose cloud score beats every other hypothesis it finds; the twin turned about the normals' vertical
// axis and shifted by the translation vote is the true pose, and the free space prefers it clearly.
TEST(SimulatedRegistration, MonumentSeenFromBothSidesIsNotFlipped) {
  const SimulatedScans scans = simulate_pair("monument", 3, 400000, 7);
  const PointCloud &source = scans.source.cloud, &target = scans.target.cloud;
  RegistrationParams params;
  params.min_scale_m = 0.1;
  params.overlap = 0.4;
  params.seed = 1;
  const RegistrationResult result = register_clouds(source, target, params);
  const TransformError error = transform_error(source.points, result.transform, scans.truth);
  EXPECT_TRUE(registration_succeeded(error, kOutdoorSuccessRmse_m))
      << "rotation " << error.rotation_deg << " deg, translation " << error.translation_m << " m";
  EXPECT_FALSE(result.ambiguous) << result.ambiguity_reason;
  // The flip is still among the hypotheses, clearly behind.
  ASSERT_GE(result.hypotheses.size(), 2u);
  EXPECT_GT(result.ambiguity_margin, 0.05);
}

// The lab's opposite corners with each scan in an arbitrary frame (rotated, and shifted up to 30 m): the files
// say nothing of where the scanners stood, so their positions come from the scans' sampling, and the free space
// breaks the half-turn symmetry as it does in the scanners' frames. Without it, geometry alone turned this pair
// by 180 degrees with a margin that looked safe.
TEST(SimulatedRegistration, OppositeCornersInArbitraryFramesAreJudgedFromEstimatedScanners) {
  for (const std::uint64_t seed : {1, 2}) {
    const SimulatedScans scans = simulate_pair("lab", 0, 200000, seed, 0, 2, sim::ScanFrame::kArbitrary);
    ASSERT_GT(scans.source.cloud.origin_m.norm(), 1.0);
    RegistrationParams params;
    params.min_scale_m = 0.1;
    params.overlap = 0.5;
    params.seed = seed;
    const RegistrationResult result = register_clouds(scans.source.cloud, scans.target.cloud, params);
    EXPECT_TRUE(result.free_space_used) << "seed " << seed;
    for (const auto& [scanner, scan] : {std::pair{&result.source_scanner, &scans.source},
                                        std::pair{&result.target_scanner, &scans.target}}) {
      EXPECT_EQ(scanner->source, ScannerSource::kEstimated) << scanner->reason;
      const Eigen::Matrix4d to_file = scan->scan_to_scene.inverse();
      const Eigen::Vector3d truth = to_file.topLeftCorner<3, 3>() * scan->station_m + to_file.topRightCorner<3, 1>();
      EXPECT_LT((scanner->position_m - truth).norm(), 0.05) << "seed " << seed;
    }
    const double error_m = rms_error_m(scans.source.cloud, result.transform, scans.truth);
    EXPECT_LT(error_m, 0.1) << "seed " << seed << (result.ambiguous ? " (flagged: " + result.ambiguity_reason + ")" : "");
  }
}

// The corridor (a tuning layout of the blind protocol): doors every 4 m, and the whole layout half-turn
// symmetric about its middle; only a few small details tell the copies apart. 4PCS finds copies that put one
// scanner where the other stood, 12 m off; the verdict cannot decide between them and, as they repeat under
// shifts, the guard searches the vote's further peaks. The truth must then lead, or be the runner-up of a
// result flagged ambiguous: never a confident copy.
TEST(SimulatedRegistration, CorridorFindsTheTrueCopyAmongThePeriodicOnes) {
  // The blind protocol's scans (at this density the automatic scale finds the 12 m copies).
  const SimulatedScans scans = simulate_pair("corridor", 0, 700000, 1);
  const PointCloud &source = scans.source.cloud, &target = scans.target.cloud;
  RegistrationParams params;
  params.seed = 1;
  const RegistrationResult result = register_clouds(source, target, params);
  auto right = [&](const Eigen::Matrix4d& t) {
    return registration_succeeded(transform_error(source.points, t, scans.truth), kIndoorSuccessRmse_m);
  };
  ASSERT_GE(result.hypotheses.size(), 2u);
  if (!right(result.transform)) {
    EXPECT_TRUE(result.ambiguous);
    EXPECT_TRUE(right(result.hypotheses[1].transform));
  }
}

// A held-out corridor layout in arbitrary frames (the blind protocol's pair 0 -> 1, read back from PLY files as the
// protocol reads them: their float coordinates decide which bases 4PCS draws): 4PCS finds only copies, and
// the best of them, 24 m off, explains as much of the source as the truth would (the free space is seen the same
// from either station) with a margin just over the verdict's; but once refined it lies 0.84 on the target surface
// where a contender lies 0.98. The figures disagree, so the result must not be confident: before the verdict
// weighed both it was a confident miss.
TEST(SimulatedRegistration, CorridorCopyThatFitsTheSurfaceWorseIsNotConfident) {
  const SimulatedScans scans = simulate_pair("corridor", 2, 700000, 1, 0, 1, sim::ScanFrame::kArbitrary);
  auto as_read = [](const PointCloud& cloud, const std::string& name) {
    const std::string path = ::testing::TempDir() + name;
    write_cloud(path, cloud);
    return read_cloud(path);
  };
  const PointCloud source = as_read(scans.source.cloud, "corridor-l2-s0.ply");
  const PointCloud target = as_read(scans.target.cloud, "corridor-l2-s1.ply");
  RegistrationParams params;
  params.min_scale_m = 0.1;
  params.overlap = 0.5;
  params.seed = 1;
  const RegistrationResult result = register_clouds(source, target, params);
  const double error_m = rms_error_m(source, result.transform, scans.truth);
  if (error_m >= kIndoorSuccessRmse_m) {
    EXPECT_TRUE(result.ambiguous) << "confidently " << error_m << " m off, margin " << result.ambiguity_margin;
  }
}

// Where a file puts its origin must not change the answer. The statuette's neighbouring views (object layout 1,
// views 0 and 1, as the blind protocol simulates them) written as a tool exporting shifted coordinates writes
// them: moved 29 m along x and y, in floats. ICP used to turn the source about the frame's origin (41 m from a
// 0.2 m object, so each linearised rotation was a large translation and float rounding a step noise far above
// its convergence bar) and hypotheses were told apart by their raw translations: the pair ended a flagged miss,
// 1.3 m off, where at the origin it registers to a tenth of a millimetre.
TEST(SimulatedRegistration, AnObjectFarFromItsFilesOriginRegistersAsAtTheOrigin) {
  const SimulatedScans scans = simulate_pair("object", 1, 40000, 1, 0, 1);
  const Eigen::Vector3f shift(29.0f, 29.0f, 0.0f);
  auto moved = [&](const PointCloud& cloud) {
    PointCloud out = cloud;
    for (Eigen::Vector3f& p : out.points) p += shift;
    return out;
  };
  Eigen::Matrix4d to_far = Eigen::Matrix4d::Identity();
  to_far.topRightCorner<3, 1>() = shift.cast<double>();
  const Eigen::Matrix4d far_truth = to_far * scans.truth * to_far.inverse();
  RegistrationParams params;
  params.min_scale_m = 0.002;
  params.overlap = 0.6;
  params.seed = 1;
  const RegistrationResult near = register_clouds(scans.source.cloud, scans.target.cloud, params);
  const PointCloud far_source = moved(scans.source.cloud), far_target = moved(scans.target.cloud);
  const RegistrationResult far = register_clouds(far_source, far_target, params);
  for (const RegistrationResult* r : {&near, &far}) {
    EXPECT_TRUE(r->well_supported && !r->ambiguous) << r->ambiguity_reason;
    EXPECT_TRUE(r->icp_converged);
  }
  EXPECT_LT(rms_error_m(scans.source.cloud, near.transform, scans.truth), 0.001);
  EXPECT_LT(rms_error_m(far_source, far.transform, far_truth), 0.001);
}

// The statuette (object layout 1): views 1 and 6 look at it from opposite sides and share nothing, and its
// near-symmetric body fits the back view onto the front turned by 180 degrees. On geometry alone the flip wins by a
// margin a free-space verdict would trust (0.09), so the geometry-only bar (ambiguity_margin.h) must flag it. Both
// views are single views of an object, so the front camera's free space applies: the turned back view puts its
// details where that camera saw through to the background, and the result is not confident. Neighbouring views
// still register, and as confidently.
TEST(SimulatedRegistration, StatuetteViewsFromOppositeSidesAreNoConfidentFlip) {
  RegistrationParams params;
  params.min_scale_m = 0.002;
  params.overlap = 0.5;
  params.seed = 1;
  const SimulatedScans opposite = simulate_pair("object", 1, 40000, 2, 1, 6);
  auto confident = [](const RegistrationResult& r) { return r.well_supported && !r.ambiguous; };
  RegistrationParams blind = params;
  blind.free_space = FreeSpaceCheck::kOff;
  const RegistrationResult without = register_clouds(opposite.source.cloud, opposite.target.cloud, blind);
  EXPECT_GE(without.ambiguity_margin, kAmbiguousMargin) << "the trap this test is about is gone";
  EXPECT_FALSE(confident(without)) << "margin " << without.ambiguity_margin;
  const RegistrationResult with = register_clouds(opposite.source.cloud, opposite.target.cloud, params);
  EXPECT_TRUE(with.free_space_used);
  EXPECT_FALSE(confident(with)) << "margin " << with.ambiguity_margin;

  const SimulatedScans neighbours = simulate_pair("object", 1, 40000, 2, 0, 1);
  const RegistrationResult right = register_clouds(neighbours.source.cloud, neighbours.target.cloud, params);
  EXPECT_TRUE(right.free_space_used);
  EXPECT_TRUE(confident(right)) << right.ambiguity_reason;
  const TransformError error = transform_error(neighbours.source.cloud.points, right.transform, neighbours.truth);
  EXPECT_LT(error.rmse_m, 0.001);
}

// Statuette views 7 and 8 (object layout 1) overlap by about 0.9, but the source has only 19 keypoints: none of the
// bases they form as narrow as an overlap of 0.4 finds a congruent set, whatever the seed. The wider bases of the
// automatic rounds do, and the pose they find is judged as any other: confident and right.
TEST(SimulatedRegistration, AGivenOverlapWhoseBasesFindNothingWidensThem) {
  RegistrationParams params;
  params.min_scale_m = 0.002;
  params.overlap = 0.4;
  params.seed = 42;
  const SimulatedScans views = simulate_pair("object", 1, 40000, 8, 7, 8);
  const RegistrationResult r = register_clouds(views.source.cloud, views.target.cloud, params);
  EXPECT_GT(r.overlap_used, params.overlap);
  EXPECT_TRUE(r.well_supported && !r.ambiguous) << r.ambiguity_reason;
  EXPECT_LT(transform_error(views.source.cloud.points, r.transform, views.truth).rmse_m, 0.001);
}

}  // namespace
}  // namespace k4reg
