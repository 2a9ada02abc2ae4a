// The "object" scene: a small statuette, ~0.2 m across (the Stanford bunny's size): a crouching body
// on a plinth, a head with two unequal ears, a tail, paws and a staff, all ellipsoids, cylinders and
// boxes. It is scanned by an object range scanner, not a TLS: ten stations every 36 deg around it
// ("object15": fifteen every 24 deg, as a real statue set's), 0.7 m away and alternately higher and
// lower, each a 35 deg camera-like frustum aimed at the statuette, with 0.15 mm range noise and no
// intensity. Nothing else is in the scene (no turntable), so neighbouring views share only the surface
// both see at an angle, ~30-60 % of each, and the body's near-symmetric ellipsoids admit many wrong
// fits: the small details must carry the registration.
#include <cmath>
#include <numbers>
#include <string>

#include "sim/layout.h"
#include "sim/scene_builder.h"

namespace k4reg::sim {
namespace {

using Eigen::Vector3d;

constexpr double kDistance_m = 0.7;            // scanner to the statuette's centre
constexpr double kHeightSwing_m = 0.12;        // stations alternate this much above and below the centre
constexpr double kFieldOfView_deg = 35.0;
constexpr double kCenterHeight_m = 0.09;       // the statuette's centre, which every station aims at
constexpr double kMaxScale = 0.1;
constexpr double kDegree = std::numbers::pi / 180.0;

// Parts in metres, the plinth's underside at z = 0; `s` scales the statuette, `ear_shift_m` and
// `staff_angle_rad` move the asymmetric details between layouts.
void add_statuette(std::vector<Primitive>& out, double s, double ear_shift_m, double staff_angle_rad) {
  const Surface clay = paint(uniform(0.6));
  out.push_back(box_between(s * Vector3d(-0.07, -0.05, 0.0), s * Vector3d(0.07, 0.05, 0.02), clay));        // plinth
  out.push_back(ellipsoid(s * Vector3d(0.0, 0.0, 0.075), s * Vector3d(0.055, 0.04, 0.055), clay));          // body
  out.push_back(ellipsoid(s * Vector3d(0.035, 0.005, 0.142), s * Vector3d(0.03, 0.025, 0.028), clay));      // head
  out.push_back(ellipsoid(s * Vector3d(0.064, 0.006, 0.138), s * Vector3d(0.007, 0.007, 0.006), clay));     // nose
  out.push_back(ellipsoid(s * Vector3d(0.028, -0.012 + ear_shift_m, 0.185), s * Vector3d(0.008, 0.005, 0.032), clay));  // long ear
  out.push_back(ellipsoid(s * Vector3d(0.046, 0.017, 0.178), s * Vector3d(0.007, 0.005, 0.022), clay));     // short ear
  out.push_back(ellipsoid(s * Vector3d(-0.058, 0.0, 0.045), s * Vector3d(0.015, 0.015, 0.015), clay));      // tail
  out.push_back(box_yawed(s * Vector3d(0.052, -0.02, 0.03), s * Vector3d(0.018, 0.01, 0.01), 0.3, clay));   // paws,
  out.push_back(box_yawed(s * Vector3d(0.05, 0.024, 0.027), s * Vector3d(0.014, 0.01, 0.007), -0.2, clay)); // unequal
  const double staff_r = 0.05 * s;
  out.push_back(cylinder(staff_r * std::cos(staff_angle_rad), staff_r * std::sin(staff_angle_rad), 0.02 * s, 0.135 * s,
                         0.006 * s, clay));  // a staff the figure leans on
}

}  // namespace

Scene make_object_scene(int layout, int views) {
  // Each ring of views has its own draws, so object15's layouts are not object's with more views.
  const std::string name = views == 10 ? "object" : "object" + std::to_string(views);
  const double step_deg = 360.0 / views;
  LayoutDice dice(name, layout);
  Scene scene = empty_scene(name, layout,
                            "statuette ~0.2 m across, object range scanner: " + std::to_string(views) +
                                " views of 35 deg every " + std::to_string(static_cast<int>(std::lround(step_deg))) +
                                " deg, 0.15 mm noise, no intensity",
                            2.0);
  scene.default_points = 40000;
  scene.default_noise_m = 0.00015;
  scene.intensity = false;
  const double s = dice.scale(kMaxScale);
  add_statuette(scene.primitives, s, dice.shift(0.006), (115.0 + dice.shift(40.0)) * kDegree);

  const Vector3d target(0.0, 0.0, kCenterHeight_m * s);
  const double distance_m = kDistance_m * dice.scale(0.2);
  for (int i = 0; i < views; ++i) {
    const double azimuth_deg = i * step_deg + dice.shift(5.0);
    const double dz = (i % 2 == 0 ? 1.0 : -1.0) * kHeightSwing_m + dice.shift(0.03);
    const double a = azimuth_deg * kDegree;
    Station station;
    station.position_m = target + Vector3d(distance_m * std::cos(a), distance_m * std::sin(a), dz);
    station.description = "view from azimuth " + std::to_string(static_cast<int>(std::lround(azimuth_deg))) + " deg, " +
                          (dz > 0.0 ? "above" : "below") + " the centre";
    station.look_at_m = target;
    station.field_of_view_deg = kFieldOfView_deg;
    scene.stations.push_back(station);
  }
  return scene;
}

}  // namespace k4reg::sim
