// The 4PCS stage on real TLS keypoints from the paper's authors (the ETH office pair PCL's KFPCS test
// uses): PCL's settings (delta 0.1 m, overlap 0.9, 100 bases) and its success criterion (rotation within
// 10 degrees, translation within 1 m of the ground truth), for several seeds.
#include <gtest/gtest.h>

#include "k4reg/io/cloud_io.h"
#include "k4reg/registration/four_pcs.h"
#include "k4reg/io/gt_pairs.h"
#include "k4reg/registration/metrics.h"

namespace k4reg {
namespace {

const std::string kOffice = std::string(K4REG_TEST_DATA_DIR) + "/eth-office/";

TEST(EthOffice, FourPcsStageRegistersTheTlsKeypointsForEverySeed) {
  const PointCloud source = read_cloud(kOffice + "office1_keypoints.pcd");
  const PointCloud target = read_cloud(kOffice + "office2_keypoints.pcd");
  const std::vector<GtPair> truth = read_gt_pairs(kOffice + "gt_pairs.log");
  ASSERT_EQ(truth.size(), 1u);
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    FourPcsParams params;
    params.delta_m = 0.1;
    params.overlap = 0.9;
    params.max_bases = 100;
    params.seed = seed;
    const FourPcsResult result = match_4pcs(source.points, target.points, params);
    // Local (origin-shifted) frames -> the files' frames, where the ground truth lives.
    Eigen::Matrix4d t = result.hypotheses.front().transform;
    t.topRightCorner<3, 1>() += target.origin_m - t.topLeftCorner<3, 3>() * source.origin_m;
    const Eigen::Matrix4d& gt = truth[0].T_target_source;
    const double rotation = rotation_angle_deg(gt.topLeftCorner<3, 3>().transpose() * t.topLeftCorner<3, 3>());
    const double translation = (t.topRightCorner<3, 1>() - gt.topRightCorner<3, 1>()).norm();
    EXPECT_LE(rotation, 10.0) << "seed " << seed;
    EXPECT_LE(translation, 1.0) << "seed " << seed;
  }
}

}  // namespace
}  // namespace k4reg
