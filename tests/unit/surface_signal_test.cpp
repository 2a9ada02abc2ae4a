// The DoG's input signals: log intensity must cancel a scan's overall gain (stations differ in range
// and incidence); without intensity the geometric signal separates planes from edges.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "k4reg/util/error.h"
#include "k4reg/registration/surface_signal.h"

namespace k4reg {
namespace {

PointCloud plane_with_intensity(std::mt19937& rng) {
  PointCloud cloud;
  std::uniform_real_distribution<float> reflectance(0.0f, 1.0f);
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 40; ++x) {
      cloud.points.emplace_back(0.05f * x, 0.05f * y, 0.0f);
      cloud.intensity.push_back(x < 20 ? 0.02f * reflectance(rng) : reflectance(rng));  // a dark half
    }
  return cloud;
}

TEST(SurfaceSignal, LogIntensityCancelsAnOverallGain) {
  std::mt19937 rng(1);
  const PointCloud cloud = plane_with_intensity(rng);
  PointCloud brighter = cloud;
  for (float& i : brighter.intensity) i *= 3.0f;
  const SurfaceSignal a = make_surface_signal(cloud, 0.05, KeypointSignal::kAuto, true);
  const SurfaceSignal b = make_surface_signal(brighter, 0.05, KeypointSignal::kAuto, true);
  ASSERT_EQ(a.name, "intensity");
  for (std::size_t i = 0; i < a.values.size(); ++i) EXPECT_NEAR(b.values[i] - a.values[i], std::log(3.0f), 1e-4f);
}

TEST(SurfaceSignal, GeometricSignalRisesOnEdges) {
  PointCloud corner;  // two perpendicular planes meeting along x = 0
  for (int a = -20; a <= 20; ++a)
    for (int b = 0; b <= 20; ++b) {
      corner.points.emplace_back(0.05f * b, 0.05f * a, 0.0f);
      corner.points.emplace_back(0.0f, 0.05f * a, 0.05f * b);
    }
  const SurfaceSignal s = make_surface_signal(corner, 0.05, KeypointSignal::kAuto, false);
  ASSERT_EQ(s.name, "geometric");
  float on_edge = 0, on_plane = 0;
  for (std::size_t i = 0; i < corner.points.size(); ++i) {
    const Eigen::Vector3f& p = corner.points[i];
    if (std::abs(p.y()) > 0.5f) continue;
    if (p.x() < 0.01f && p.z() < 0.01f) on_edge = std::max(on_edge, s.values[i]);
    if (p.x() > 0.6f) on_plane = std::max(on_plane, s.values[i]);
  }
  EXPECT_GT(on_edge, 0.1f);
  EXPECT_LT(on_plane, 0.01f);
}

TEST(SurfaceSignal, IntensityRequestedWithoutIntensityIsAnError) {
  PointCloud cloud;
  cloud.points = {Eigen::Vector3f::Zero(), Eigen::Vector3f::UnitX(), Eigen::Vector3f::UnitY(), Eigen::Vector3f::UnitZ()};
  EXPECT_THROW(make_surface_signal(cloud, 0.05, KeypointSignal::kIntensity, false), Error);
}

}  // namespace
}  // namespace k4reg
