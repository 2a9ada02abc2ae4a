// match_4pcs with point labels (the pipeline's DoG extremum signs): labels that agree keep the true pose
// and drop chance congruent sets before verification; labels that never agree fall back to the
// unlabelled search rather than fail; a label list of the wrong length is refused.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>
#include <vector>

#include "k4reg/util/error.h"
#include "k4reg/registration/four_pcs.h"
#include "k4reg/registration/metrics.h"

namespace k4reg {
namespace {

struct Scene {
  std::vector<Eigen::Vector3f> source, target;
  std::vector<std::uint8_t> source_labels, target_labels;
  Eigen::Matrix4d truth = Eigen::Matrix4d::Identity();  // source -> target
};

// Random points in a room-sized box, the target a rigid motion of them with 5 mm noise; random labels
// that each target point shares with its source point.
Scene scene() {
  Scene s;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> x(0.0f, 10.0f), y(0.0f, 8.0f), z(0.0f, 3.0f);
  std::normal_distribution<float> noise(0.0f, 0.005f);
  std::bernoulli_distribution coin;
  s.truth.topLeftCorner<3, 3>() = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  s.truth.topRightCorner<3, 1>() = Eigen::Vector3d(2.0, -1.0, 0.3);
  const Eigen::Affine3f t(s.truth.cast<float>());
  for (int i = 0; i < 400; ++i) {
    const Eigen::Vector3f p(x(rng), y(rng), z(rng));
    s.source.push_back(p);
    s.target.push_back(t * p + Eigen::Vector3f(noise(rng), noise(rng), noise(rng)));
    s.source_labels.push_back(coin(rng));
  }
  s.target_labels = s.source_labels;
  return s;
}

FourPcsParams params() {
  FourPcsParams p;
  p.delta_m = 0.05;
  p.overlap = 0.8;
  p.seed = 3;
  return p;
}

double rotation_error_deg(const FourPcsResult& r, const Eigen::Matrix4d& truth) {
  return rotation_angle_deg(r.hypotheses.front().transform.topLeftCorner<3, 3>().transpose() *
                            truth.topLeftCorner<3, 3>());
}

TEST(FourPcs, AgreeingLabelsKeepThePoseAndDropChanceSets) {
  const Scene s = scene();
  const FourPcsResult plain = match_4pcs(s.source, s.target, params());
  FourPcsParams labelled = params();
  labelled.source_labels = &s.source_labels;
  labelled.target_labels = &s.target_labels;
  const FourPcsResult with_labels = match_4pcs(s.source, s.target, labelled);
  EXPECT_LT(rotation_error_deg(plain, s.truth), 0.5);
  EXPECT_LT(rotation_error_deg(with_labels, s.truth), 0.5);
  // Random binary labels keep 1 in 16 chance sets, and every true one.
  EXPECT_LT(with_labels.congruent_sets * 4, plain.congruent_sets);
  EXPECT_GT(with_labels.congruent_sets, 0u);
}

TEST(FourPcs, LabelsThatNeverAgreeFallBackToTheUnlabelledSearch) {
  // Every source point a maximum, every target point a minimum: no set can agree.
  const Scene s = scene();
  const std::vector<std::uint8_t> maxima(s.source.size(), 1), minima(s.target.size(), 0);
  FourPcsParams labelled = params();
  labelled.source_labels = &maxima;
  labelled.target_labels = &minima;
  const FourPcsResult result = match_4pcs(s.source, s.target, labelled);
  const FourPcsResult plain = match_4pcs(s.source, s.target, params());
  EXPECT_LT(rotation_error_deg(result, s.truth), 0.5);
  EXPECT_EQ(result.congruent_sets, plain.congruent_sets);
}

TEST(FourPcs, OneLabelPerPointIsRequired) {
  const Scene s = scene();
  const std::vector<std::uint8_t> too_few(10, 0);
  FourPcsParams labelled = params();
  labelled.source_labels = &too_few;
  labelled.target_labels = &s.target_labels;
  try {
    match_4pcs(s.source, s.target, labelled);
    FAIL() << "expected kInvalidArgument";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
  }
}

}  // namespace
}  // namespace k4reg
