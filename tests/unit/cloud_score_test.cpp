// The symmetry guard's cloud score and its free-space evidence: a surface placed where the target scanner saw
// through counts against a pose, unless the scanner would have met that surface at grazing incidence; one
// placed in open sky counts against it only where it would have faced the scanner.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "k4reg/registration/free_space.h"
#include "k4reg/registration/symmetry_guard.h"

namespace k4reg {
namespace {

constexpr float kSpacing_m = 0.05f;

// The target scanner at the origin, 1.5 m above a floor that runs 20 m ahead to an end wall.
IcpPyramid::Stage corridor_end() {
  IcpPyramid::Stage stage;
  stage.voxel_m = kSpacing_m;
  for (float x = 0.5f; x <= 20.0f; x += kSpacing_m)
    for (float y = -3.0f; y <= 3.0f; y += kSpacing_m) stage.points.emplace_back(x, y, -1.5f);
  for (float y = -3.0f; y <= 3.0f; y += kSpacing_m)
    for (float z = -1.5f; z <= 1.5f; z += kSpacing_m) stage.points.emplace_back(20.0f, y, z);
  stage.grid = std::make_unique<NeighborGrid>(stage.points, 2.5 * kSpacing_m);
  stage.normals = estimate_normals(stage.points, *stage.grid, 2.5 * kSpacing_m);
  return stage;
}

// A 1 m square patch centred at `centre` (10 m ahead by default), in the plane through `a` and `b` (unit axes).
IcpPyramid::Stage patch(const Eigen::Vector3f& a, const Eigen::Vector3f& b,
                        const Eigen::Vector3f& centre = Eigen::Vector3f(10, 0, 0)) {
  IcpPyramid::Stage stage;
  stage.voxel_m = kSpacing_m;
  for (float u = -0.5f; u <= 0.5f; u += kSpacing_m)
    for (float v = -0.5f; v <= 0.5f; v += kSpacing_m) stage.points.push_back(centre + u * a + v * b);
  return stage;
}

double score(const IcpPyramid::Stage& source) {
  const IcpPyramid::Stage target = corridor_end();
  const Viewpoint scanner = Viewpoint::at(Eigen::Vector3f::Zero());
  const FreeSpaceImage free_space(target.points, scanner, 3 * kSpacing_m);
  const ScanViews views{&free_space, scanner, scanner};
  const float tau = 1.5f * kSpacing_m;
  return cloud_score(scored_source(source, 100000), target, *target.grid, tau, Eigen::Matrix4d::Identity(), &views, 1.0);
}

TEST(CloudScore, ASurfaceFacingTheScannerWhereItSawThroughCountsAgainstThePose) {
  // Across the corridor, facing the scanner: every point lies where the scanner saw the end wall behind it.
  EXPECT_LT(score(patch(Eigen::Vector3f::UnitY(), Eigen::Vector3f::UnitZ())), -0.4);
}

TEST(CloudScore, ASurfaceTheScannerWouldMeetAtGrazingIncidenceIsNoEvidence) {
  // Along the line of sight (a far side wall, seen edge on): scanners return little or nothing from such
  // surfaces, so that the scanner saw past it says nothing.
  EXPECT_EQ(score(patch(Eigen::Vector3f::UnitX(), Eigen::Vector3f::UnitZ())), 0.0);
}

TEST(CloudScore, OpenSkyCountsAgainstASurfaceThatWouldHaveFacedTheScanner) {
  // Beside the corridor's floor, 8 m to the left and 10 degrees down, the scanner got no return at all in a
  // wide patch of directions while it reached 20 m ahead: nothing stood there.
  const Eigen::Vector3f beside(0, 8, -1.4f);
  EXPECT_LT(score(patch(Eigen::Vector3f::UnitX(), Eigen::Vector3f::UnitZ(), beside)), -0.4);
  // Turned 70 degrees away from the line of sight, the same patch could have been too dark to return
  // anything from afar: no evidence.
  const float turn = 70.0f * static_cast<float>(M_PI) / 180;
  EXPECT_EQ(score(patch(Eigen::Vector3f(std::cos(turn), std::sin(turn), 0), Eigen::Vector3f::UnitZ(), beside)), 0.0);
}

}  // namespace
}  // namespace k4reg
