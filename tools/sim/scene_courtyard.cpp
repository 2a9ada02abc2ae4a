// The "courtyard" scene: a 30 x 22 m courtyard enclosed by four 13 m facades with four storeys of
// windows (dark rooms behind the glass) and doors on the ground floor, open to the sky. In it: two
// trees, a round fountain, a kiosk and a parked car. The facades' window grids repeat every 3.5 m in
// both directions and the long facades face each other, so the building alone is nearly periodic and
// half-turn symmetric; the fountain, the kiosk, the trees and the car decide the pose. Much of every
// scan hits glass (mostly lost) and the open sky, so the hit fraction is low.
#include <numbers>

#include "sim/layout.h"
#include "sim/scene_builder.h"

namespace k4reg::sim {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

constexpr double kLength_m = 30.0, kWidth_m = 22.0, kHeight_m = 13.0;
constexpr double kBay_m = 3.5;        // window spacing along the facades
constexpr double kStorey_m = 3.1;     // sills of the four storeys are this far apart
constexpr double kMaxScale = 0.12;
constexpr double kRoomDepth_m = 4.5;  // of the rooms seen through the windows
constexpr double kScannerHeight_m = 1.6;
constexpr double kHorizontal = std::numbers::pi / 2;

struct CourtyardLayout {
  double length_m, width_m;
  Vector2d fountain_m, kiosk_m, car_m;
  double car_yaw_rad = 0.0;
  std::vector<Vector2d> trees_m;
};

CourtyardLayout courtyard_layout(LayoutDice& dice) {
  CourtyardLayout c;
  c.length_m = kLength_m * dice.scale(kMaxScale);
  c.width_m = kWidth_m * dice.scale(kMaxScale);
  auto place = [&](double fx, double fy, double jitter_m) {
    return Vector2d(fx * c.length_m + dice.shift(jitter_m), fy * c.width_m + dice.shift(jitter_m));
  };
  c.fountain_m = place(0.45, 0.55, 2.0);
  c.kiosk_m = place(0.8, 0.25, 1.5);
  c.car_m = place(0.25, 0.2, 1.5);
  c.car_yaw_rad = 0.15 + dice.shift(0.4);
  c.trees_m = {place(0.2, 0.75, 1.5), place(0.75, 0.75, 1.5)};
  return c;
}

// One facade's openings: a door or a window in the ground floor of each bay (doors in every third),
// windows above, centred so that the grid is symmetric about the facade's middle.
std::vector<Opening> facade_openings(double length_m) {
  std::vector<Opening> openings;
  const int bays = static_cast<int>(length_m / kBay_m);
  const double first = 0.5 * (length_m - (bays - 1) * kBay_m);
  for (int i = 0; i < bays; ++i) {
    const double u = first + i * kBay_m;
    if (i % 3 == 1)
      openings.push_back({u - 0.6, u + 0.6, 0.0, 2.4, true});
    else
      openings.push_back({u - 0.7, u + 0.7, 0.9, 2.6});
    for (int storey = 1; storey < 4; ++storey) {
      const double sill = 0.9 + storey * kStorey_m;
      openings.push_back({u - 0.7, u + 0.7, sill, sill + 1.7});
    }
  }
  return openings;
}

void add_car(std::vector<Primitive>& out, const Vector2d& at, double yaw) {
  const Eigen::Matrix3d r = Eigen::AngleAxisd(yaw, Vector3d::UnitZ()).toRotationMatrix();
  const Vector3d c(at.x(), at.y(), 0.0);
  out.push_back(box_yawed(c + Vector3d(0, 0, 0.6), Vector3d(2.2, 0.9, 0.3), yaw, paint(uniform(0.55))));       // body
  out.push_back(box_yawed(c + r * Vector3d(-0.2, 0, 1.15), Vector3d(1.2, 0.8, 0.25), yaw, paint(uniform(0.15))));  // cabin
  for (const double wx : {-1.4, 1.4})
    for (const double wy : {-0.85, 0.85})
      out.push_back(box_yawed(c + r * Vector3d(wx, wy, 0.32), Vector3d(0.32, 0.1, 0.32), yaw, paint(uniform(0.08))));  // wheels
}

void add_courtyard_objects(std::vector<Primitive>& out, const CourtyardLayout& c) {
  // Fountain: a basin ring (two cylinders of stone), a column and a bowl.
  const Vector2d& f = c.fountain_m;
  out.push_back(cylinder(f.x(), f.y(), 0.0, 0.55, 2.2, paint(bricks(0.6, 0.4, 0.6, 0.25, 0.015, 0.06))));
  out.push_back(cylinder(f.x(), f.y(), 0.0, 1.6, 0.25, paint(uniform(0.65))));
  out.push_back(ellipsoid(Vector3d(f.x(), f.y(), 1.7), Vector3d(0.8, 0.8, 0.2), paint(uniform(0.6))));
  // Kiosk with an awning.
  const Vector2d& k = c.kiosk_m;
  out.push_back(box_between(Vector3d(k.x() - 1.5, k.y() - 1.0, 0.0), Vector3d(k.x() + 1.5, k.y() + 1.0, 2.6), paint(uniform(0.5))));
  out.push_back(box_yawed(Vector3d(k.x(), k.y() + 1.5, 2.4), Vector3d(1.6, 0.5, 0.04), 0.0, paint(stripes(0.8, 0.2, 0.5, 0.25))));
  for (const auto& t : c.trees_m) {
    out.push_back(cylinder(t.x(), t.y(), 0.0, 3.0, 0.2, paint(stripes(0.28, 0.2, 0.15, 0.05))));
    out.push_back(ellipsoid(Vector3d(t.x(), t.y(), 5.0), Vector3d(2.6, 2.6, 2.4), paint(uniform(0.3), Material::kFoliage)));
  }
  add_car(out, c.car_m, c.car_yaw_rad);
}

}  // namespace

Scene make_courtyard_scene(int layout) {
  LayoutDice dice("courtyard", layout);
  const CourtyardLayout c = courtyard_layout(dice);
  Scene scene = empty_scene("courtyard", layout,
                            "courtyard ~30 x 22 m in four 13 m facades of windows; trees, fountain, kiosk, parked car", 80.0);

  RoomSpec facades{c.length_m, c.width_m, kHeight_m, 0.3, kRoomDepth_m, {}, {}};
  for (int i = 0; i < 4; ++i) {
    facades.surfaces[i] = paint(stripes(0.5, 0.68, kStorey_m, 0.25, kHorizontal));  // string courses
    facades.openings[i] = facade_openings(i % 2 == 0 ? c.length_m : c.width_m);
  }
  add_room_walls(scene.primitives, facades);
  Surface paving{checker(0.42, 0.5, 0.8, 0.1), {}, Material::kOpaque};
  scene.primitives.push_back(rect(Vector3d::Zero(), Vector3d::UnitX(), Vector3d::UnitY(), c.length_m, c.width_m, paving));
  add_courtyard_objects(scene.primitives, c);

  const double l = c.length_m, w = c.width_m;
  auto at = [&](double fx, double fy) { return Vector3d(fx * l + dice.shift(0.8), fy * w + dice.shift(0.8), kScannerHeight_m); };
  scene.stations = {
      {at(0.12, 0.45), "west side, by the car", {}},
      {at(0.6, 0.15), "south side, between the fountain and the kiosk", {}},
      {at(0.88, 0.6), "east side, north of the kiosk", {}},
      {at(0.45, 0.88), "north side, between the trees", {}},
  };
  // Stations 4-23, for projects of many setups: every 4 m or so round the courtyard, 2.5 m from the facades
  // (clear of the car, the kiosk and the trees), anticlockwise from the south-west corner.
  const double inset = 2.5, ring_l = l - 2 * inset, ring_w = w - 2 * inset;
  constexpr int kRing = 20;
  for (int k = 0; k < kRing; ++k) {
    double u = k * 2.0 * (ring_l + ring_w) / kRing;  // distance along the ring
    Vector2d xy;
    if (u < ring_l) xy = {inset + u, inset};
    else if ((u -= ring_l) < ring_w) xy = {l - inset, inset + u};
    else if ((u -= ring_w) < ring_l) xy = {l - inset - u, w - inset};
    else xy = {inset, w - inset - (u - ring_l)};
    scene.stations.push_back({Vector3d(xy.x(), xy.y(), kScannerHeight_m), "round the courtyard, 2.5 m from the facades", {}});
  }
  return scene;
}

}  // namespace k4reg::sim
