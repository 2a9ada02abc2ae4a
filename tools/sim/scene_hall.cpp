// The "hall" scene: an empty 20 x 12 x 5 m hall whose geometry is mirror-symmetric about the vertical
// plane x = length / 2 and about y = width / 2, hence also half-turn symmetric about its vertical axis:
// windows, doors, columns, radiators and lights all come in symmetric sets (only the door handles, a few
// cm, sit on one side of each leaf). The only element that breaks the symmetry is one free-standing
// partition (4 x 2.5 m) in one half; a poster and a floor marking break it a little in intensity. So a
// registration that misses the partition's few per cent of the points finds the half turn as good as
// the truth, and the opposite-corner pair sees the partition from its two sides.
#include <numbers>

#include "sim/layout.h"
#include "sim/scene_builder.h"

namespace k4reg::sim {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

constexpr double kLength_m = 20.0, kWidth_m = 12.0, kHeight_m = 5.0;
constexpr double kMaxScale = 0.15;  // layouts scale each dimension by up to this share
constexpr double kHorizontal = std::numbers::pi / 2;
constexpr double kPartitionLength_m = 4.0, kPartitionHeight_m = 2.5, kPartitionThickness_m = 0.12;
constexpr double kScannerHeight_m = 1.5;
constexpr double kStationJitter_m = 0.4;  // layouts move each station by up to this in x and y

struct HallLayout {
  double length_m, width_m, height_m;
  Vector2d partition_center_m;  // the partition runs along y, in the half x < length / 2 or the other
  Vector2d poster_shift_m;      // where the few intensity-only asymmetries sit
};

HallLayout hall_layout(LayoutDice& dice) {
  HallLayout h;
  h.length_m = kLength_m * dice.scale(kMaxScale);
  h.width_m = kWidth_m * dice.scale(kMaxScale);
  h.height_m = kHeight_m * dice.scale(kMaxScale);
  // Between the first and the middle row of columns (0.25 and 0.5 of the length), a little off the
  // centre line so that not even the y mirror maps it onto itself.
  double x = h.length_m * (0.36 + dice.shift(0.03));
  if (dice.flip()) x = h.length_m - x;
  double y = h.width_m * (0.42 + dice.shift(0.04));
  if (dice.flip()) y = h.width_m - y;
  h.partition_center_m = {x, y};
  h.poster_shift_m = {dice.shift(0.8), dice.shift(1.0)};  // the poster stays between two windows
  return h;
}

// u positions (from a wall's start) of `count` openings evenly spread along a wall: symmetric about its middle.
std::vector<double> evenly(double length_m, int count) {
  std::vector<double> u;
  for (int i = 0; i < count; ++i) u.push_back(length_m * (i + 0.5) / count);
  return u;
}

void add_shell(std::vector<Primitive>& out, const HallLayout& h) {
  const double l = h.length_m, w = h.width_m, ht = h.height_m;
  RoomSpec room{l, w, ht, 0.35, 0.0, {}, {}};
  const Surface wall{stripes(0.7, 0.25, 100.0, 0.15, kHorizontal), {}, Material::kOpaque};  // dark skirting
  room.surfaces = {wall, wall, wall, wall};
  for (const int side : {0, 2}) {  // long walls: five tall windows each
    for (const double u : evenly(l, 5)) room.openings[side].push_back({u - 0.9, u + 0.9, 0.25 * ht, 0.75 * ht});
  }
  for (const int side : {1, 3}) {  // short walls: a central double door between two high windows
    room.openings[side] = {{0.25 * w - 0.8, 0.25 * w + 0.8, 0.5 * ht, 0.8 * ht},
                           {0.5 * w - 0.9, 0.5 * w + 0.9, 0.0, 2.4, true},
                           {0.75 * w - 0.8, 0.75 * w + 0.8, 0.5 * ht, 0.8 * ht}};
  }
  // One poster in the east half of the south wall: intensity only.
  room.surfaces[0].zones.push_back(
      PatternZone{Vector2d(0.6 * l + h.poster_shift_m.x(), 1.7), Vector2d(0.5, 0.7), 0.0, checker(0.85, 0.1, 0.2)});
  add_room_walls(out, room);

  Surface floor{grid(0.45, 0.3, 1.0, 0.02), {}, Material::kOpaque};
  // A taped rectangle on the floor near the north-west, the hall's one floor marking.
  floor.zones.push_back(PatternZone{Vector2d(0.2 * l + h.poster_shift_m.x(), 0.7 * w + h.poster_shift_m.y()),
                                    Vector2d(1.5, 1.0), 0.0, stripes(0.85, 0.45, 3.0, 2.9)});
  out.push_back(rect(Vector3d::Zero(), Vector3d::UnitX(), Vector3d::UnitY(), l, w, floor));
  out.push_back(rect(Vector3d(0, 0, ht), Vector3d::UnitX(), Vector3d::UnitY(), l, w, paint(grid(0.75, 0.55, 1.2, 0.03))));

  // Columns on a symmetric 3 x 2 grid, radiators under every long-wall window, two rows of hanging lights.
  for (const double fx : {0.25, 0.5, 0.75})
    for (const double fy : {1.0 / 3.0, 2.0 / 3.0})
      out.push_back(cylinder(fx * l, fy * w, 0.0, ht, 0.3, paint(stripes(0.6, 0.2, 1.5, 0.15, kHorizontal))));
  const Surface radiator = paint(stripes(0.7, 0.35, 0.08, 0.03));
  for (const double u : evenly(l, 5))
    for (const double y : {0.05, w - 0.15})
      out.push_back(box_between(Vector3d(u - 0.7, y, 0.15), Vector3d(u + 0.7, y + 0.1, 0.75), radiator));
  for (const double u : evenly(l, 4))
    for (const double fy : {0.25, 0.75})
      out.push_back(box_between(Vector3d(u - 0.7, fy * w - 0.15, ht - 0.7), Vector3d(u + 0.7, fy * w + 0.15, ht - 0.6),
                                paint(uniform(0.95))));
}

}  // namespace

Scene make_hall_scene(int layout) {
  LayoutDice dice("hall", layout);
  const HallLayout h = hall_layout(dice);
  Scene scene = empty_scene("hall", layout,
                            "empty hall ~20 x 12 x 5 m, mirror- and half-turn symmetric except one free-standing partition", 80.0);
  add_shell(scene.primitives, h);
  // The symmetry breaker: a free-standing partition wall with a pin-board band.
  const Vector2d& c = h.partition_center_m;
  scene.primitives.push_back(box_between(
      Vector3d(c.x() - 0.5 * kPartitionThickness_m, c.y() - 0.5 * kPartitionLength_m, 0.0),
      Vector3d(c.x() + 0.5 * kPartitionThickness_m, c.y() + 0.5 * kPartitionLength_m, kPartitionHeight_m),
      paint(stripes(0.55, 0.3, 1.0, 0.4, kHorizontal))));

  const double l = h.length_m, w = h.width_m;
  auto at = [&](double x, double y, double z) {
    return Vector3d(x + dice.shift(kStationJitter_m), y + dice.shift(kStationJitter_m), z);
  };
  scene.stations = {
      {at(1.8, 1.8, kScannerHeight_m), "south-west corner", {}},
      {at(l - 1.8, w - 1.8, kScannerHeight_m), "north-east corner, opposite station 0 (the partition hides part of the view)", {}},
      {at(0.62 * l, 0.5 * w, 1.0), "east of the centre, 1.0 m high (pairs with station 3)", {}},
      {at(0.8 * l, 0.15 * w, 0.68 * h.height_m), "south-east, raised to 2/3 of the hall's height (3.4 m at layout 0), above station 2", {}},
      {at(1.8, w - 1.8, kScannerHeight_m), "north-west corner", {}},
  };
  return scene;
}

}  // namespace k4reg::sim
