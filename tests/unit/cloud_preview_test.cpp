// The preview of registered clouds: sizes within the budget, distances that tell a good pose from a bad one,
// the frame and offset, keypoints, unregistered project scans, determinism and bad parameters.
#include <Eigen/LU>
#include <gtest/gtest.h>

#include "k4reg/geometry/rigid_motion.h"
#include "k4reg/io/cloud_io.h"
#include "k4reg/qa/cloud_preview.h"
#include "k4reg/util/error.h"

namespace k4reg {
namespace {

const std::string kBunny = std::string(K4REG_TEST_DATA_DIR) + "/bunny/";

// The cloud moved by m.
PointCloud moved(const PointCloud& cloud, const Eigen::Matrix4d& m) {
  std::vector<Eigen::Vector3d> points;
  for (const Eigen::Vector3f& p : cloud.points)
    points.push_back(m.topLeftCorner<3, 3>() * (p.cast<double>() + cloud.origin_m) + m.topRightCorner<3, 1>());
  return make_local_cloud(points, {});
}

Eigen::Matrix4d motion(double angle_rad, const Eigen::Vector3d& shift) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = rotation_exp(Eigen::Vector3d(0.3, 1.0, 0.2).normalized() * angle_rad);
  m.topRightCorner<3, 1>() = shift;
  return m;
}

float max_distance(const PreviewCloud& cloud) { return *std::max_element(cloud.distance_m.begin(), cloud.distance_m.end()); }

class CloudPreviewTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // The target far from the origin (as survey coordinates are); the source is the same scan moved away.
    target = moved(read_cloud(kBunny + "bun000.ply"), motion(0.0, {512000.0, 5240000.0, 300.0}));
    const Eigen::Matrix4d away = motion(1.0, {0.3, -0.2, 0.1});
    source = moved(target, away);
    truth.transform = away.inverse();  // source -> target
    truth.min_scale_m_used = 0.002;
    truth.source_keypoint_positions_m = {Eigen::Vector3d(source.origin_m)};
    truth.target_keypoint_positions_m = {Eigen::Vector3d(target.origin_m)};
  }
  PointCloud source, target;
  RegistrationResult truth;
};

TEST_F(CloudPreviewTest, TheTruePoseLeavesNoDistanceAndAWrongOneDoes) {
  PreviewParams params;
  params.max_points = 20000;
  const CloudPreview good = make_pair_preview(source, target, truth, params);
  ASSERT_EQ(good.clouds.size(), 2u);
  EXPECT_EQ(good.clouds[0].name, "source");
  EXPECT_EQ(good.clouds[0].points, source.size());
  EXPECT_EQ(good.clouds[0].xyz.size() + good.clouds[1].xyz.size(), 20000u);
  EXPECT_EQ(good.clouds[0].xyz.size(), good.clouds[0].distance_m.size());
  EXPECT_DOUBLE_EQ(good.distance_cap_m, 0.006);  // three minimum scales
  EXPECT_EQ(good.offset_m, target.origin_m);
  EXPECT_LT(max_distance(good.clouds[0]), 1e-4);  // the same points, to float precision around the offset
  EXPECT_LT(max_distance(good.clouds[1]), 1e-4);

  RegistrationResult wrong = truth;
  wrong.transform = motion(0.0, {0.004, 0.0, 0.0}) * truth.transform;  // 4 mm off
  const CloudPreview bad = make_pair_preview(source, target, wrong, params);
  double sum = 0;
  for (float d : bad.clouds[0].distance_m) sum += d;
  EXPECT_GT(sum / bad.clouds[0].distance_m.size(), 5e-4);
  EXPECT_LE(max_distance(bad.clouds[0]), 0.006f);  // capped
}

TEST_F(CloudPreviewTest, PointsAndKeypointsLieInTheTargetFrameAroundTheOffset) {
  PreviewParams params;
  params.max_points = 1000;
  const CloudPreview preview = make_pair_preview(source, target, truth, params);
  // The source keypoint (the source's origin) moved by the transform, minus the offset.
  Eigen::Vector4d k = Eigen::Vector4d::Ones();
  k.head<3>() = source.origin_m;
  const Eigen::Vector3d expected = (truth.transform * k).head<3>() - target.origin_m;
  ASSERT_EQ(preview.clouds[0].keypoints.size(), 1u);
  EXPECT_LT((preview.clouds[0].keypoints[0].cast<double>() - expected).norm(), 1e-5);
  EXPECT_LT(preview.clouds[1].keypoints[0].norm(), 1e-6f);
  // Every kept target point is one of the target's own (local) points.
  for (const Eigen::Vector3f& p : preview.clouds[1].xyz) EXPECT_LT(p.norm(), 0.2f);
}

TEST_F(CloudPreviewTest, IsDeterministicAndKeepsSmallCloudsWhole) {
  PreviewParams params;
  params.max_points = 50000;
  const CloudPreview a = make_pair_preview(source, target, truth, params);
  const CloudPreview b = make_pair_preview(source, target, truth, params);
  EXPECT_EQ(a.clouds[0].xyz, b.clouds[0].xyz);
  EXPECT_EQ(a.clouds[1].distance_m, b.clouds[1].distance_m);
  params.max_points = kMaxPreviewPoints;
  const CloudPreview whole = make_pair_preview(source, target, truth, params);
  EXPECT_EQ(whole.clouds[0].xyz.size(), source.size());
  EXPECT_EQ(whole.clouds[1].xyz.size(), target.size());
}

TEST_F(CloudPreviewTest, RefusesBadParameters) {
  PreviewParams params;
  params.max_points = 0;
  EXPECT_THROW(make_pair_preview(source, target, truth, params), Error);
  params.max_points = kMaxPreviewPoints + 1;
  EXPECT_THROW(make_pair_preview(source, target, truth, params), Error);
  params.max_points = 100;
  params.distance_cap_m = -1.0;
  EXPECT_THROW(make_pair_preview(source, target, truth, params), Error);
}

TEST_F(CloudPreviewTest, ProjectScansNotRegisteredHaveNoPoints) {
  ProjectResult project;
  project.reference = 1;
  project.scans.resize(3);
  project.scans[0].registered = true;
  project.scans[0].pose = truth.transform;
  project.scans[1].registered = true;  // the reference: identity
  project.scans[2].registered = false;
  ProjectLink link;
  link.accepted = true;
  link.min_scale_m_used = 0.002;
  project.links.push_back(link);
  const std::vector<PointCloud> scans{source, target, source};
  PreviewParams params;
  params.max_points = 9000;
  const CloudPreview preview = make_project_preview(scans, {"a.ply", "b.ply", "c.ply"}, project, params);
  ASSERT_EQ(preview.clouds.size(), 3u);
  EXPECT_EQ(preview.clouds[2].name, "c.ply");
  EXPECT_EQ(preview.clouds[2].points, source.size());
  EXPECT_TRUE(preview.clouds[2].xyz.empty());
  EXPECT_EQ(preview.clouds[0].xyz.size(), 4500u);  // the budget goes to the registered scans
  EXPECT_LT(max_distance(preview.clouds[0]), 1e-4);  // an unregistered scan is nobody's neighbour, the rest agree
  EXPECT_THROW(make_project_preview(scans, {"a.ply"}, project, params), Error);
}

}  // namespace
}  // namespace k4reg
