// The free-space image of a terrestrial scan: what the scanner saw to be empty, including open sky where it
// looked and got no return at all, and what it cannot tell; and of a range camera's view of an object.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>

#include "k4reg/registration/free_space.h"

namespace k4reg {
namespace {

using Seen = FreeSpaceImage::Seen;

struct Plaza {
  float ground_z_m = -1.6f;      // the scanner stands 1.6 m above the ground
  float ground_radius_m = 60.0f; // ground returns end here (range, grazing incidence)
  float facade_x_m = 20.0f;      // a facade across the plaza, facing the scanner
  float facade_half_width_m = 15.0f;
  float facade_top_z_m = 10.0f;
  float min_elevation_deg = -60.0f, max_elevation_deg = 90.0f;  // the scanner's field of view
  // A dark window in the facade (no return): centre (y, z) and half size.
  float window_y_m = 0.0f, window_z_m = 4.0f, window_half_m = 0.0f;

  std::optional<Eigen::Vector3f> first_return(const Eigen::Vector3f& u) const {
    std::optional<Eigen::Vector3f> hit;
    if (u.x() > 0) {
      const Eigen::Vector3f p = u * (facade_x_m / u.x());
      const bool in_window = std::abs(p.y() - window_y_m) < window_half_m && std::abs(p.z() - window_z_m) < window_half_m;
      if (std::abs(p.y()) <= facade_half_width_m && p.z() >= ground_z_m && p.z() <= facade_top_z_m && !in_window) hit = p;
    }
    if (u.z() < 0) {
      const Eigen::Vector3f p = u * (ground_z_m / u.z());
      if (p.head<2>().norm() <= ground_radius_m && (!hit || p.norm() < hit->norm())) hit = p;
    }
    return hit;
  }

  // Rays on a regular angular grid (as a terrestrial scanner samples), first returns only.
  std::vector<Eigen::Vector3f> scan(float step_deg = 0.25f) const {
    std::vector<Eigen::Vector3f> points;
    for (float el = min_elevation_deg; el <= max_elevation_deg; el += step_deg) {
      const float e = el * static_cast<float>(M_PI) / 180;
      const float az_step = step_deg / std::max(0.05f, std::cos(e));
      for (float az = -180; az < 180; az += az_step) {
        const float a = az * static_cast<float>(M_PI) / 180;
        const Eigen::Vector3f u(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
        if (const auto p = first_return(u)) points.push_back(*p);
      }
    }
    return points;
  }
};

Eigen::Vector3f at(float range_m, float azimuth_deg, float elevation_deg) {
  const float a = azimuth_deg * static_cast<float>(M_PI) / 180, e = elevation_deg * static_cast<float>(M_PI) / 180;
  return range_m * Eigen::Vector3f(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
}

TEST(FreeSpace, SpaceInFrontOfTheFirstReturnIsEmptyAndBehindItOccluded) {
  const FreeSpaceImage image(Plaza{}.scan(), Viewpoint::at(Eigen::Vector3f::Zero()), 0.2);
  EXPECT_EQ(image.classify(at(10, 0, 10)), Seen::kEmpty);     // in front of the facade
  EXPECT_EQ(image.classify(Eigen::Vector3f(20, 0, 2)), Seen::kSurface);
  EXPECT_EQ(image.classify(at(40, 0, 5)), Seen::kOccluded);   // behind it
}

TEST(FreeSpace, OpenSkyWithinTheScannersReachContradictsAPointPlacedThere) {
  const FreeSpaceImage image(Plaza{}.scan(), Viewpoint::at(Eigen::Vector3f::Zero()), 0.2);
  // Behind the scanner, 15 degrees up: no return anywhere near, while the scanner reached 60 m elsewhere and
  // returned from as high up (the facade's top, 27 degrees up).
  EXPECT_EQ(image.classify(at(15, 180, 15)), Seen::kOpen);
  // Far beyond anything the scanner returned from: it may simply not reach that far.
  EXPECT_EQ(image.classify(at(500, 180, 15)), Seen::kUnknown);
  // Higher than anything it returned from: its field of view may end below.
  EXPECT_EQ(image.classify(at(15, 180, 45)), Seen::kUnknown);
}

TEST(FreeSpace, DirectionsTheScannerNeverLookedAtAreNoEvidence) {
  // A profiler-like field of view (as a Velodyne's -30 to +10 degrees): above it, no return says nothing.
  Plaza band;
  band.min_elevation_deg = -30, band.max_elevation_deg = 10;
  const FreeSpaceImage image(band.scan(), Viewpoint::at(Eigen::Vector3f::Zero()), 0.2);
  EXPECT_EQ(image.classify(at(15, 180, 40)), Seen::kUnknown);
  EXPECT_EQ(image.classify(at(15, 0, 60)), Seen::kUnknown);
}

TEST(FreeSpace, ASmallHoleInAWallIsNotOpenSky) {
  // A dark window of 2 x 2 m at 20 m (about 6 degrees): the scanner saw the wall all around it, so a point
  // behind the window is hidden, not contradicted.
  Plaza plaza;
  plaza.window_half_m = 1.0f;
  const FreeSpaceImage image(plaza.scan(), Viewpoint::at(Eigen::Vector3f::Zero()), 0.2);
  const Eigen::Vector3f behind_window = 1.25f * Eigen::Vector3f(20, 0, 4);
  EXPECT_EQ(image.classify(behind_window), Seen::kUnknown);
}

// A range camera's view of two domes (radius 0.1 m, 0.3 m apart) from far above: a parallel image along +z.
std::vector<Eigen::Vector3f> domes_seen_from_above() {
  std::vector<Eigen::Vector3f> points;
  for (const float centre_x : {0.0f, 0.3f})
    for (float x = -0.1f; x <= 0.1f; x += 0.001f)
      for (float y = -0.1f; y <= 0.1f; y += 0.001f)
        if (x * x + y * y < 0.01f) points.emplace_back(centre_x + x, y, std::sqrt(0.01f - x * x - y * y));
  return points;
}

TEST(FreeSpace, AnObjectViewSeenAlongItsCameraDirection) {
  const Viewpoint camera = Viewpoint::along(Eigen::Vector3f::UnitZ());
  const FreeSpaceImage image(domes_seen_from_above(), camera, 0.006, 0.002);
  EXPECT_EQ(image.classify(Eigen::Vector3f(0, 0, 0.13f)), Seen::kEmpty);    // above a dome's top: seen through
  EXPECT_EQ(image.classify(Eigen::Vector3f(0, 0, 0.1f)), Seen::kSurface);
  EXPECT_EQ(image.classify(Eigen::Vector3f(0, 0, 0.0f)), Seen::kOccluded);  // under the dome
  // Between the domes: the camera saw the background there, all around.
  EXPECT_EQ(image.classify(Eigen::Vector3f(0.15f, 0, 0.05f)), Seen::kOpen);
  // Beyond the image's edge: outside what the camera is known to have looked at.
  EXPECT_EQ(image.classify(Eigen::Vector3f(1.0f, 0, 0.05f)), Seen::kUnknown);
  // The camera's rays are parallel: every point is seen along -z.
  EXPECT_TRUE(camera.ray_to(Eigen::Vector3f(5, 6, 7)).isApprox(-Eigen::Vector3f::UnitZ()));
  const Eigen::Affine3f turned(Eigen::AngleAxisf(static_cast<float>(M_PI) / 2, Eigen::Vector3f::UnitX()));
  EXPECT_TRUE(camera.moved(turned).toward_scanner.isApprox(-Eigen::Vector3f::UnitY(), 1e-6f));
}

}  // namespace
}  // namespace k4reg
