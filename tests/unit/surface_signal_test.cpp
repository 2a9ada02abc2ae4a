// The DoG's input signals: log intensity must cancel a scan's overall gain (stations differ in range
// and incidence) without amplifying the receiver's additive noise on dark returns; without intensity
// the geometric signal separates planes from edges.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "k4reg/error.h"
#include "k4reg/surface_signal.h"

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

TEST(SurfaceSignal, AdditiveNoiseOnDarkReturnsIsNotAmplified) {
  // Receiver noise of 0.01 on returns in [0, 1]: a log without an offset would turn it into changes of
  // order 1 on the darkest points; the offset (0.3 of the range) bounds the change by noise / 0.3.
  std::mt19937 rng(2);
  const PointCloud cloud = plane_with_intensity(rng);
  PointCloud noisy = cloud;
  std::normal_distribution<float> noise(0.0f, 0.01f);
  for (float& i : noisy.intensity) i = std::max(0.0f, i + noise(rng));
  const SurfaceSignal a = make_surface_signal(cloud, 0.05, KeypointSignal::kIntensity, true);
  const SurfaceSignal b = make_surface_signal(noisy, 0.05, KeypointSignal::kIntensity, true);
  double largest = 0;
  for (std::size_t i = 0; i < a.values.size(); ++i) largest = std::max(largest, double(std::abs(b.values[i] - a.values[i])));
  EXPECT_LT(largest, 0.05 / 0.3 + 0.05);  // noise within 5 sigma, plus the shift of the minimum and range
  EXPECT_GT(largest, 0.0);
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
