// The project's least-squares solver: poses recovered from consistent links, the reference kept fixed,
// an outlier link down-weighted, misfits reported in metres.
#include <gtest/gtest.h>

#include <random>

#include "k4reg/geometry/rigid_motion.h"
#include "k4reg/project/pose_graph.h"

namespace k4reg {
namespace {

// Scans about their frames' origins, 10 m across.
const ScanExtent kAtOrigin10m{Eigen::Vector3d::Zero(), 10.0};

Eigen::Matrix4d pose(const Eigen::Vector3d& w, const Eigen::Vector3d& t) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = rotation_exp(w);
  m.topRightCorner<3, 1>() = t;
  return m;
}

// Five scans on a ring, every pair linked by its true relative transform (p_to = T * p_from).
struct Ring {
  std::vector<Eigen::Matrix4d> truth;
  std::vector<PoseGraphLink> links;
  Ring() {
    std::mt19937 rng(3);
    std::normal_distribution<double> n(0.0, 1.0);
    truth.push_back(Eigen::Matrix4d::Identity());
    for (int i = 1; i < 5; ++i)
      truth.push_back(pose(Eigen::Vector3d(0.1 * n(rng), 0.1 * n(rng), 1.2 * i), Eigen::Vector3d(3 * n(rng), 3 * n(rng), n(rng))));
    for (std::size_t a = 0; a < 5; ++a)
      for (std::size_t b = a + 1; b < 5; ++b) links.push_back({a, b, rigid_inverse(truth[b]) * truth[a], kAtOrigin10m, 1.0});
  }
};

double max_error_m(const std::vector<Eigen::Matrix4d>& poses, const std::vector<Eigen::Matrix4d>& truth) {
  double worst = 0;
  for (std::size_t i = 0; i < poses.size(); ++i) worst = std::max(worst, displacement_m(rigid_inverse(truth[i]) * poses[i], kAtOrigin10m));
  return worst;
}

TEST(PoseGraph, RecoversPosesFromPerturbedStartAndKeepsTheReference) {
  const Ring ring;
  std::vector<Eigen::Matrix4d> start = ring.truth;
  for (std::size_t i = 1; i < start.size(); ++i) start[i] = pose(Eigen::Vector3d(0.05, -0.03, 0.08), Eigen::Vector3d(0.4, -0.2, 0.3)) * start[i];
  const PoseGraphResult r = optimize_pose_graph(start, ring.links, {});
  EXPECT_LT(max_error_m(r.poses, ring.truth), 1e-6);
  EXPECT_TRUE(r.poses[0].isApprox(Eigen::Matrix4d::Identity()));
  EXPECT_LT(r.final_cost, 1e-10);
  EXPECT_GT(r.initial_cost, 1.0);
  for (double m : r.residual_m) EXPECT_LT(m, 1e-6);
}

TEST(PoseGraph, AnotherReferenceStaysWhereItIs) {
  const Ring ring;
  std::vector<Eigen::Matrix4d> start(5, Eigen::Matrix4d::Identity());
  start[2] = ring.truth[2];
  // Start the others from a chain of links, slightly off.
  for (std::size_t i : {1, 3, 4}) start[i] = pose(Eigen::Vector3d(0.02, 0, 0), Eigen::Vector3d(0.1, 0, 0)) * ring.truth[i];
  start[0] = pose(Eigen::Vector3d(0, 0.02, 0), Eigen::Vector3d(0, 0.1, 0));
  PoseGraphParams params;
  params.fixed = 2;
  const PoseGraphResult r = optimize_pose_graph(start, ring.links, params);
  EXPECT_TRUE(r.poses[2].isApprox(ring.truth[2], 1e-12));
  EXPECT_LT(max_error_m(r.poses, ring.truth), 1e-6);
}

TEST(PoseGraph, HuberKernelKeepsAnOutlierLinkFromBendingTheGraph) {
  Ring ring;
  ring.links[3].measured = pose(Eigen::Vector3d(0, 0, 0.3), Eigen::Vector3d(2, 0, 0)) * ring.links[3].measured;
  PoseGraphParams robust;
  robust.huber_m = 0.01;
  const PoseGraphResult with = optimize_pose_graph(ring.truth, ring.links, robust);
  const PoseGraphResult without = optimize_pose_graph(ring.truth, ring.links, {});
  EXPECT_LT(max_error_m(with.poses, ring.truth), 0.5 * max_error_m(without.poses, ring.truth));
  // The bad link shows as the one misfit.
  for (std::size_t e = 0; e < ring.links.size(); ++e) {
    if (e == 3) {
      EXPECT_GT(with.residual_m[e], 1.0);
    } else {
      EXPECT_LT(with.residual_m[e], 0.5);
    }
  }
}

// Links with a millimetre of noise and one 5 cm off, under a kernel at a 10 cm tolerance (what the loops allow):
// one solve lets the bad link bend the ring; the second, at twice the median residual the links show, all but
// ignores it.
TEST(PoseGraph, SecondSolveAtTheLinksOwnScaleIgnoresALinkFarOffTheRest) {
  Ring ring;
  std::mt19937 rng(5);
  std::normal_distribution<double> mm(0.0, 0.001);
  for (PoseGraphLink& link : ring.links)
    link.measured = pose(Eigen::Vector3d(mm(rng), mm(rng), mm(rng)) / 10.0, Eigen::Vector3d(mm(rng), mm(rng), mm(rng))) *
                    link.measured;
  ring.links[3].measured = pose(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.05, 0, 0)) * ring.links[3].measured;
  PoseGraphParams tolerant;
  tolerant.huber_m = 0.1;
  const double once = max_error_m(optimize_pose_graph(ring.truth, ring.links, tolerant).poses, ring.truth);
  const double twice = max_error_m(optimize_pose_graph_robustly(ring.truth, ring.links, tolerant).poses, ring.truth);
  EXPECT_LT(twice, 0.5 * once) << "once " << once << " m, twice " << twice << " m";
  // Fewer than three links: one solve, the same as optimize_pose_graph.
  const std::vector<PoseGraphLink> two(ring.links.begin(), ring.links.begin() + 2);
  const std::vector<Eigen::Matrix4d> three(ring.truth.begin(), ring.truth.begin() + 3);
  EXPECT_TRUE(optimize_pose_graph_robustly(three, two, tolerant).poses[2].isApprox(
      optimize_pose_graph(three, two, tolerant).poses[2], 1e-12));
}

TEST(PoseGraph, RefusesLinksOutOfRange) {
  const Ring ring;
  std::vector<PoseGraphLink> links = ring.links;
  links[0].to = 9;
  EXPECT_THROW(optimize_pose_graph(ring.truth, links, {}), std::exception);
  PoseGraphParams params;
  params.fixed = 5;
  EXPECT_THROW(optimize_pose_graph(ring.truth, ring.links, params), std::exception);
}

}  // namespace
}  // namespace k4reg
