// The "corridor" scene: a 40 m corridor, 2.4 m wide and 3 m high, with a door every 4 m on both sides,
// a niche between every two doors and a ceiling light every 2 m (half the door period, so the corridor
// is periodic with 4 m), glazed ends. The layout is also half-turn symmetric about the corridor's middle.
// Only a few small details break both symmetries: one open door with the room behind it, a notice
// board, a fire extinguisher and a bench. A pose shifted by one period along the corridor, or turned
// by 180 deg, explains nearly all of a scan as well as the truth does.
#include <algorithm>
#include <numbers>

#include "sim/layout.h"
#include "sim/scene_builder.h"

namespace k4reg::sim {
namespace {

using Eigen::Vector3d;

constexpr double kLength_m = 40.0, kWidth_m = 2.4, kHeight_m = 3.0;
constexpr double kPeriod_m = 4.0;          // doors; niches sit half way between them
constexpr double kLightSpacing_m = 2.0;    // half the period, so the lights keep the corridor periodic
constexpr double kMaxScale = 0.12;         // layouts scale the period, width and height by up to this share
constexpr double kDoorWidth_m = 0.9, kDoorHeight_m = 2.1;
constexpr double kWallThickness_m = 0.25;
constexpr double kRoomDepth_m = 3.5;       // of the room behind the open door
constexpr double kScannerHeight_m = 1.5;
constexpr double kHorizontal = std::numbers::pi / 2;

struct CorridorLayout {
  double period_m, width_m, height_m;
  int doors_per_side = 10;
  int open_door = 2;          // index on the south side (from the west end)
  double board_x_m = 0.0;     // notice board on the north wall
  double extinguisher_x_m = 0.0, bench_x_m = 0.0;
  bool swap_sides = false;    // the extinguisher and the bench change walls
  double length_m() const { return period_m * doors_per_side; }
};

CorridorLayout corridor_layout(LayoutDice& dice) {
  CorridorLayout c;
  c.period_m = kPeriod_m * dice.scale(kMaxScale);
  c.width_m = kWidth_m * dice.scale(kMaxScale);
  c.height_m = kHeight_m * dice.scale(kMaxScale);
  c.open_door = dice.varied() ? std::clamp(2 + static_cast<int>(std::lround(dice.shift(1.5))), 0, c.doors_per_side - 1) : 2;
  // Details sit between a door and a niche (at a quarter period) so they do not collide with either.
  auto quarter = [&](int slot) { return c.period_m * (slot + 0.75); };
  c.board_x_m = quarter(5 + static_cast<int>(std::lround(dice.shift(2.0))));
  c.extinguisher_x_m = quarter(3 + static_cast<int>(std::lround(dice.shift(1.5))));
  c.bench_x_m = quarter(7 + static_cast<int>(std::lround(dice.shift(1.5))));
  c.swap_sides = dice.flip();
  return c;
}

void add_shell(std::vector<Primitive>& out, const CorridorLayout& c) {
  const double l = c.length_m(), w = c.width_m, h = c.height_m;
  RoomSpec room{l, w, h, kWallThickness_m, 0.0, {}, {}};
  const Surface wall{stripes(0.72, 0.3, 100.0, 0.12, kHorizontal), {}, Material::kOpaque};  // skirting
  room.surfaces = {wall, wall, wall, wall};
  // A door at the middle of every period, a niche between doors; the north wall runs from x = l back
  // to 0, so the same u list puts its doors opposite the south ones.
  for (const int side : {0, 2})
    for (int i = 0; i < c.doors_per_side; ++i) {
      const double door_u = c.period_m * (i + 0.5), niche_u = c.period_m * (i + 1.0);
      const bool open = side == 0 && i == c.open_door;
      room.openings[side].push_back({door_u - 0.5 * kDoorWidth_m, door_u + 0.5 * kDoorWidth_m, 0.0, kDoorHeight_m, !open,
                                     open ? kRoomDepth_m : 0.0});
      if (i + 1 < c.doors_per_side) room.openings[side].push_back({niche_u - 0.4, niche_u + 0.4, 0.9, 2.0, false, 0.5});
    }
  for (const int side : {1, 3}) room.openings[side].push_back({0.5 * w - 0.7, 0.5 * w + 0.7, 0.9, 0.9 * h});
  add_room_walls(out, room);

  out.push_back(rect(Vector3d::Zero(), Vector3d::UnitX(), Vector3d::UnitY(), l, w, paint(grid(0.4, 0.25, 0.6, 0.015))));
  out.push_back(rect(Vector3d(0, 0, h), Vector3d::UnitX(), Vector3d::UnitY(), l, w, paint(grid(0.8, 0.6, 0.6, 0.02))));
  const double light_spacing_m = kLightSpacing_m * c.period_m / kPeriod_m;
  for (double x = 0.5 * light_spacing_m; x < l; x += light_spacing_m)
    out.push_back(box_between(Vector3d(x - 0.6, 0.5 * w - 0.2, h - 0.06), Vector3d(x + 0.6, 0.5 * w + 0.2, h), paint(uniform(0.95))));
}

// What breaks the periodicity: the open door (leaf swung into the room, the room's side walls and floor),
// a notice board, a fire extinguisher and a bench.
void add_details(std::vector<Primitive>& out, const CorridorLayout& c) {
  const double w = c.width_m, door_x = c.period_m * (c.open_door + 0.5);
  const double x0 = door_x - 0.5 * kDoorWidth_m, x1 = door_x + 0.5 * kDoorWidth_m;
  // The room behind the open door: its back wall is where the opening's recess ends (same paint, so
  // the two coincide), side walls, floor and ceiling from the corridor wall's back face.
  const double room_x0 = x0 - 1.2, room_x1 = x1 + 1.6, back_y = -kRoomDepth_m, depth = kRoomDepth_m - kWallThickness_m;
  const Surface room_wall = paint(uniform(0.3));
  out.push_back(rect(Vector3d(room_x0, back_y, 0.0), Vector3d::UnitX(), Vector3d::UnitZ(), room_x1 - room_x0, c.height_m, room_wall));
  for (const double x : {room_x0, room_x1})
    out.push_back(rect(Vector3d(x, back_y, 0.0), Vector3d::UnitY(), Vector3d::UnitZ(), depth, c.height_m, room_wall));
  for (const double z : {0.0, c.height_m})
    out.push_back(rect(Vector3d(room_x0, back_y, z), Vector3d::UnitX(), Vector3d::UnitY(), room_x1 - room_x0, depth, room_wall));
  out.push_back(box_between(Vector3d(x0 + 0.05, -kWallThickness_m - 0.85, 0.0),
                            Vector3d(x0 + 0.09, -kWallThickness_m - 0.05, kDoorHeight_m - 0.02), paint(uniform(0.42))));

  const double board_y = w, near_y = c.swap_sides ? w : 0.0, far_y = c.swap_sides ? 0.0 : w;
  out.push_back(box_between(Vector3d(c.board_x_m - 0.35, board_y - 0.03, 1.1), Vector3d(c.board_x_m + 0.35, board_y, 1.9),
                            paint(checker(0.85, 0.3, 0.1, 0.2))));
  const double ext_y = near_y + (near_y > 0.0 ? -0.15 : 0.15);
  out.push_back(cylinder(c.extinguisher_x_m, ext_y, 0.0, 0.6, 0.09, paint(uniform(0.5))));
  // A short bench, 5 cm off the wall so that it clears the door casings at the narrowest layouts.
  const double bench_y0 = far_y > 0.0 ? far_y - 0.5 : 0.05;
  out.push_back(box_between(Vector3d(c.bench_x_m - 0.45, bench_y0, 0.4), Vector3d(c.bench_x_m + 0.45, bench_y0 + 0.45, 0.46),
                            paint(uniform(0.45))));
  for (const double dx : {-0.38, 0.38})
    out.push_back(box_between(Vector3d(c.bench_x_m + dx - 0.04, bench_y0 + 0.05, 0.0),
                              Vector3d(c.bench_x_m + dx + 0.04, bench_y0 + 0.4, 0.4), paint(uniform(0.2))));
}

}  // namespace

Scene make_corridor_scene(int layout) {
  LayoutDice dice("corridor", layout);
  const CorridorLayout c = corridor_layout(dice);
  Scene scene = empty_scene("corridor", layout,
                            "40 m corridor, 2.4 m wide: doors every 4 m, niches, lights every 2 m; few asymmetric details", 60.0);
  add_shell(scene.primitives, c);
  add_details(scene.primitives, c);
  const double l = c.length_m();
  for (const auto& [share, name] : std::vector<std::pair<double, std::string>>{
           {0.2, "west, 8 m from the west end"}, {0.5, "middle, 20 m"}, {0.8, "east, 32 m"}}) {
    const Vector3d p(share * l + dice.shift(0.6), 0.5 * c.width_m + dice.shift(0.25), kScannerHeight_m);
    scene.stations.push_back({p, name + " (neighbouring stations overlap)", {}});
  }
  return scene;
}

}  // namespace k4reg::sim
