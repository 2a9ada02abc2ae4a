// The evidence a refined pose is judged on: its support and whether it lies on the target surface.
#include "k4reg/registration/pose_score.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <random>

#include "k4reg/io/cloud_io.h"
#include "k4reg/io/gt_pairs.h"
#include "k4reg/geometry/voxel_grid.h"
#include "k4reg/registration/contender_verdict.h"
#include "k4reg/registration/prepared_scan.h"
#include "k4reg/registration/registration.h"

namespace k4reg {
namespace {

const std::string kBunny = std::string(K4REG_TEST_DATA_DIR) + "/bunny/";

struct Scene {
  IcpParams icp;
  IcpPyramid source, target;
  Eigen::Matrix4d truth;
};

Scene bunny(double sigma_m) {
  GtPair pair;
  for (const GtPair& p : read_gt_pairs(kBunny + "gt_pairs.log"))
    if (p.source == "bun045.ply" && p.target == "bun000.ply") pair = p;
  Scene s;
  s.icp.voxel_m = sigma_m;
  s.source =
      make_icp_pyramid(voxel_grid(read_cloud(kBunny + pair.source), sigma_m).cloud.points, s.icp, PyramidRole::kSource);
  s.target =
      make_icp_pyramid(voxel_grid(read_cloud(kBunny + pair.target), sigma_m).cloud.points, s.icp, PyramidRole::kTarget);
  s.truth = pair.T_target_source;
  return s;
}

// A true pose lies on the surface; turned 20 degrees about the truth, the clouds still cross and touch,
// but what comes near the target surface no longer lies on it.
TEST(PoseScore, TruePosesLieOnTheSurfaceWrongOnesOnlyTouchIt) {
  const Scene s = bunny(0.002);
  const PoseScorer scorer(s.source, s.target, nullptr, 0.5);
  const Eigen::Matrix4d truth = refine_icp(s.source, s.target, s.truth, s.icp).transform;
  EXPECT_GE(scorer.surface_agreement(truth), kMinSurfaceAgreement);
  EXPECT_GT(scorer.score(truth), 0.8);

  Eigen::Matrix4d off = Eigen::Matrix4d::Identity();
  off.topLeftCorner<3, 3>() = Eigen::AngleAxisd(20.0 * M_PI / 180.0, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Eigen::Matrix4d wrong = off * s.truth;
  EXPECT_LT(scorer.surface_agreement(wrong), 0.5);
  EXPECT_LT(scorer.surface_agreement(wrong), scorer.surface_agreement(truth));
}

TEST(PoseScore, NothingNearGivesZero) {
  const Scene s = bunny(0.002);
  const PoseScorer scorer(s.source, s.target, nullptr, 0.5);
  Eigen::Matrix4d far = s.truth;
  far(0, 3) += 10.0;
  EXPECT_EQ(scorer.surface_agreement(far), 0.0);
  EXPECT_LE(scorer.score(far), 0.0);
}

PointCloud with_noise(const PointCloud& cloud, double sigma_m, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> n(0.0f, static_cast<float>(sigma_m));
  PointCloud noisy = cloud;
  for (Eigen::Vector3f& p : noisy.points) p += Eigen::Vector3f(n(rng), n(rng), n(rng));
  return noisy;
}

// Two samplings of one clean surface agree almost perfectly; range noise at the scale lowers what they reach
// (the bar a true pose must clear falls with it), a true pose between two noisy scans still clears it, and a
// pose 20 degrees off does not.
TEST(PoseScore, SelfAgreementFallsWithNoiseAndSetsTheBar) {
  GtPair pair;
  for (const GtPair& p : read_gt_pairs(kBunny + "gt_pairs.log"))
    if (p.source == "bun045.ply" && p.target == "bun000.ply") pair = p;
  constexpr double kSigma = 0.002, kNoise_m = 0.003;
  const PointCloud clean = read_cloud(kBunny + pair.target);
  EXPECT_GE(PreparedScan(clean).surface_self_agreement(kSigma, nullptr), 0.97);

  const PointCloud source = with_noise(read_cloud(kBunny + pair.source), kNoise_m, 1);
  const PointCloud target = with_noise(clean, kNoise_m, 2);
  const double self = PreparedScan(target).surface_self_agreement(kSigma, nullptr);
  EXPECT_LT(self, 0.8);
  IcpParams icp;
  icp.voxel_m = kSigma;
  const IcpPyramid from = make_icp_pyramid(voxel_grid(source, kSigma).cloud.points, icp, PyramidRole::kSource);
  const IcpPyramid to = make_icp_pyramid(voxel_grid(target, kSigma).cloud.points, icp, PyramidRole::kTarget);
  const PoseScorer scorer(from, to, nullptr, 0.5);
  EXPECT_GE(scorer.surface_agreement(refine_icp(from, to, pair.T_target_source, icp).transform), kMinSurfaceAgreement * self);
  Eigen::Matrix4d off = Eigen::Matrix4d::Identity();
  off.topLeftCorner<3, 3>() = Eigen::AngleAxisd(20.0 * M_PI / 180.0, Eigen::Vector3d::UnitX()).toRotationMatrix();
  EXPECT_LT(scorer.surface_agreement(off * pair.T_target_source), kMinSurfaceAgreement * self);
}

}  // namespace
}  // namespace k4reg
