// The "lab" scene: a 15 x 10 x 3.5 m room like the paper's lab. The shell is symmetric under a half
// turn about the room's centre (windows on both long walls, a door in each short wall, pillars and
// ceiling lights on a symmetric grid); the furniture, posters and floor markings break the symmetry,
// so a registration must rely on them to pick the right one of two near-equal solutions.
#include <numbers>

#include "sim/scene_builder.h"

namespace k4reg::sim {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

constexpr double kLength_m = 15.0, kWidth_m = 10.0, kHeight_m = 3.5;
constexpr double kHorizontal = std::numbers::pi / 2;  // stripe angle for bands across v (horizontal on walls)

PatternZone zone(double cu, double cv, double hu, double hv, const Pattern& p) {
  return PatternZone{Vector2d(cu, cv), Vector2d(hu, hv), 0.0, p};
}

// Painted wall with a dark skirting board.
Surface wall_paint(std::vector<PatternZone> posters) {
  return Surface{stripes(0.7, 0.25, 100.0, 0.1, kHorizontal), std::move(posters), Material::kOpaque};
}

std::vector<Opening> long_wall_windows() {
  std::vector<Opening> windows;
  for (const double c : {3.75, 7.5, 11.25}) windows.push_back({c - 0.9, c + 0.9, 0.9, 2.6});
  return windows;
}

void add_shell(std::vector<Primitive>& out) {
  const Vector3d x = Vector3d::UnitX(), y = Vector3d::UnitY();
  const Opening door{7.8, 8.8, 0.0, 2.1, true};
  // South wall (y = 0): checkerboard poster between the first two windows.
  add_wall(out, WallSpec{Vector3d(0, 0, 0), x, y, kLength_m, kHeight_m, 0.3, 0.0,
                         wall_paint({zone(5.5, 1.8, 0.4, 0.6, checker(0.85, 0.08, 0.2))}), long_wall_windows()});
  // North wall (y = 10), running from x = 15 to 0: a dot poster and a diagonal-stripe poster.
  add_wall(out, WallSpec{Vector3d(kLength_m, kWidth_m, 0), -x, -y, kLength_m, kHeight_m, 0.3, 0.0,
                         wall_paint({zone(5.65, 1.75, 0.45, 0.55, dots(0.8, 0.1, 0.25, 0.07)),
                                     zone(13.7, 1.75, 0.5, 0.45, stripes(0.85, 0.15, 0.2, 0.08, std::numbers::pi / 4))}),
                         long_wall_windows()});
  // West wall (x = 0), running from y = 10 to 0; door at y 1.2..2.2.
  add_wall(out, WallSpec{Vector3d(0, kWidth_m, 0), -y, x, kWidth_m, kHeight_m, 0.3, 0.0, wall_paint({}), {door}});
  // East wall (x = 15), running from y = 0 to 10; door at y 7.8..8.8; a fine checkerboard poster.
  add_wall(out, WallSpec{Vector3d(kLength_m, 0, 0), y, -x, kWidth_m, kHeight_m, 0.3, 0.0,
                         wall_paint({zone(1.2, 1.6, 0.4, 0.4, checker(0.9, 0.1, 0.1))}), {door}});

  // Floor tiles with tape: a taped zone around the east desk, a walkway line, a hatched zone by the east door.
  Surface floor{grid(0.4, 0.28, 0.6, 0.02), {}, Material::kOpaque};
  const Pattern tape = uniform(0.8);
  floor.zones = {zone(13.0, 3.9, 0.8, 0.03, tape),  zone(13.0, 6.1, 0.8, 0.03, tape),
                 zone(12.2, 5.0, 0.03, 1.1, tape),  zone(13.8, 5.0, 0.03, 1.1, tape),
                 zone(4.75, 4.95, 4.25, 0.04, tape), zone(14.2, 8.3, 0.8, 0.7, stripes(0.3, 0.8, 0.3, 0.12, std::numbers::pi / 4))};
  out.push_back(rect(Vector3d::Zero(), x, y, kLength_m, kWidth_m, floor));
  out.push_back(rect(Vector3d(0, 0, kHeight_m), x, y, kLength_m, kWidth_m, paint(grid(0.75, 0.55, 0.6, 0.03))));

  // Symmetric structure: pillars with dark bands, flush ceiling lights, radiators under the windows.
  for (const double px : {3.75, 7.5, 11.25})
    for (const double py : {3.5, 6.5}) out.push_back(cylinder(px, py, 0.0, kHeight_m, 0.25, paint(stripes(0.6, 0.2, 1.2, 0.12, kHorizontal))));
  for (const double lx : {2.5, 6.0, 9.0, 12.5})
    for (const double ly : {3.0, 7.0})
      out.push_back(box_between(Vector3d(lx - 0.6, ly - 0.15, kHeight_m - 0.05), Vector3d(lx + 0.6, ly + 0.15, kHeight_m),
                                paint(uniform(0.95))));
  const Surface radiator = paint(stripes(0.7, 0.35, 0.08, 0.03));
  for (const double rx : {3.75, 7.5, 11.25}) {
    out.push_back(box_between(Vector3d(rx - 0.6, 0.05, 0.15), Vector3d(rx + 0.6, 0.15, 0.7), radiator));
    if (rx < 11.0)  // the podium stands under the north-east window
      out.push_back(box_between(Vector3d(rx - 0.6, kWidth_m - 0.15, 0.15), Vector3d(rx + 0.6, kWidth_m - 0.05, 0.7), radiator));
  }
}

// A desk: top and two side panels; yaw 0 = long side along x.
void add_desk(std::vector<Primitive>& out, double x, double y, double yaw, bool monitor) {
  const Eigen::Matrix3d r = Eigen::AngleAxisd(yaw, Vector3d::UnitZ()).toRotationMatrix();
  const Vector3d c(x, y, 0.0);
  out.push_back(box_yawed(c + Vector3d(0, 0, 0.735), Vector3d(0.8, 0.4, 0.015), yaw, paint(uniform(0.55))));
  for (const double side : {-0.77, 0.77})
    out.push_back(box_yawed(c + r * Vector3d(side, 0, 0.36), Vector3d(0.015, 0.35, 0.36), yaw, paint(uniform(0.3))));
  if (monitor)
    out.push_back(box_yawed(c + r * Vector3d(0.1, 0.2, 0.98), Vector3d(0.28, 0.025, 0.23), yaw, paint(uniform(0.06))));
}

void add_furniture(std::vector<Primitive>& out) {
  // Furniture is where the room's half-turn symmetry breaks, as in a real lab: desks mostly in the
  // west half, cabinets along the north wall only.
  add_desk(out, 2.6, 5.5, 0.0, true);
  add_desk(out, 2.6, 6.9, 0.0, false);
  add_desk(out, 5.6, 8.6, 0.0, true);
  add_desk(out, 5.2, 2.2, std::numbers::pi / 2, true);
  add_desk(out, 10.5, 2.6, 0.0, false);  // station 3's scanner stands on this one
  add_desk(out, 13.0, 6.2, std::numbers::pi / 2, true);

  // Cabinets with door gaps (vertical dark lines on every face).
  const Surface cabinet = paint(stripes(0.55, 0.1, 0.5, 0.012));
  out.push_back(box_between(Vector3d(0.0, 7.0, 0.0), Vector3d(0.5, 8.0, 2.0), cabinet));
  out.push_back(box_between(Vector3d(4.8, 9.5, 0.0), Vector3d(5.8, 10.0, 2.0), cabinet));
  out.push_back(box_between(Vector3d(5.8, 9.6, 0.0), Vector3d(6.5, 10.0, 0.9), paint(uniform(0.35))));
  out.push_back(box_between(Vector3d(7.6, 9.5, 0.0), Vector3d(8.6, 10.0, 2.0), cabinet));
  out.push_back(box_between(Vector3d(14.55, 0.3, 0.0), Vector3d(15.0, 1.9, 1.1), cabinet));  // a low sideboard

  // Whiteboards in dark frames on the short walls (at half-turn symmetric places, different contents).
  const Surface frame = paint(uniform(0.2));
  out.push_back(box_between(Vector3d(0.0, 3.46, 0.86), Vector3d(0.012, 5.54, 2.14), frame));
  out.push_back(box_between(Vector3d(0.0, 3.5, 0.9), Vector3d(0.02, 5.5, 2.1), paint(uniform(0.9))));
  out.push_back(box_between(Vector3d(kLength_m - 0.012, 4.46, 0.86), Vector3d(kLength_m, 6.54, 2.14), frame));
  out.push_back(box_between(Vector3d(kLength_m - 0.02, 4.5, 0.9), Vector3d(kLength_m, 6.5, 2.1),
                            paint(stripes(0.9, 0.3, 0.15, 0.04, kHorizontal))));

  // A podium with one step under the north-east window, and a fire extinguisher by a pillar.
  out.push_back(box_between(Vector3d(9.4, 8.6, 0.0), Vector3d(12.6, kWidth_m, 0.35), paint(uniform(0.45))));
  out.push_back(box_between(Vector3d(10.0, 8.2, 0.0), Vector3d(12.0, 8.6, 0.175), paint(stripes(0.45, 0.85, 100.0, 0.05, kHorizontal))));
  out.push_back(cylinder(7.85, 3.5, 0.0, 0.6, 0.09, paint(uniform(0.5))));
}

}  // namespace

Scene make_lab_scene() {
  Scene scene;
  scene.name = "lab";
  scene.description = "indoor room 15 x 10 x 3.5 m, half-turn symmetric shell, asymmetric furniture";
  scene.default_max_range_m = 80.0;
  add_shell(scene.primitives);
  add_furniture(scene.primitives);
  scene.stations = {
      {Vector3d(1.8, 1.8, 1.5), "south-west corner", {}},
      {Vector3d(13.2, 8.2, 1.5), "north-east corner (opposite station 0)", {}},
      {Vector3d(6.0, 5.0, 1.5), "centre, between the pillars", {}},
      {Vector3d(10.5, 2.6, 2.5), "on the desk by the south windows, 2.5 m high", {}},
      {Vector3d(4.0, 8.5, 1.5), "north-west, by the cabinets", {}},
      {Vector3d(8.0, 8.0, 1.5), "north of the centre", {}},
  };
  return scene;
}

}  // namespace k4reg::sim
