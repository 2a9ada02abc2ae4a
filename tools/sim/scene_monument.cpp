// The "monument" scene: a city gate on a flat paved plaza, 16 m wide, 8 m deep and 17 m high, with a
// barrel-vaulted passage along y, buttress piers at its four corners and an attic. The gate is
// symmetric front to back: a half turn about the vertical through its centre maps it onto itself, so
// the front (south) and back (north) scans each see "the same" face. Only the surroundings break the
// symmetry: trees at irregular places, lamp posts on one side, and a long facade ~45 m east of the gate
// that both the front and the back station see at a grazing angle. Stations stand ~25 m from the gate,
// so at ~1.5 M points the front/back pair shares the gate's top, the passage, the facade and the crowns.
#include <numbers>
#include <tuple>

#include "sim/layout.h"
#include "sim/scene_builder.h"

namespace k4reg::sim {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

constexpr double kHalfWidth_m = 8.0, kHalfDepth_m = 4.0, kBlockHeight_m = 13.0;
constexpr double kPassageHalfSpan_m = 3.2, kSpring_m = 6.5;  // vault springs 6.5 m above the ground
constexpr double kAtticHeight_m = 4.0;
constexpr double kFacadeX_m = 45.0;
constexpr double kGroundHalf_m = 120.0;
constexpr double kMaxScale = 0.12;   // layouts scale the gate (and the station distances) by up to this share
constexpr double kScannerHeight_m = 1.6;
constexpr double kHorizontal = std::numbers::pi / 2;

struct MonumentLayout {
  double scale = 1.0;           // of the gate
  double station_distance_m = 25.0;
  Vector2d tree_shift_m = Vector2d::Zero();
  bool facade_west = false;     // the facade (and the lamps) on the other side
  double facade_x_m() const { return facade_west ? -kFacadeX_m : kFacadeX_m; }
};

// The gate, centred on the origin: everything here comes in half-turn symmetric pairs.
void add_gate(std::vector<Primitive>& out, double s) {
  const Surface stone = paint(bricks(0.58, 0.38, 1.0 * s, 0.5 * s, 0.02, 0.08));
  const Surface moulding = paint(uniform(0.64));
  const double hw = kHalfWidth_m * s, hd = kHalfDepth_m * s, h = kBlockHeight_m * s;
  out.push_back(Primitive{ArchBlock{Box{Vector3d(0, 0, 0.5 * h), Eigen::Matrix3d::Identity(), Vector3d(hw, hd, 0.5 * h)},
                                    kPassageHalfSpan_m * s, kSpring_m * s - 0.5 * h},
                          stone});
  // Buttress piers at the four corners, stepping in below the cornice.
  for (const double sx : {-1.0, 1.0})
    for (const double sy : {-1.0, 1.0}) {
      const Vector3d corner(sx * hw, sy * hd, 0.0);
      out.push_back(box_between(corner + Vector3d(-sx * 2.0 * s, 0.0, 0.0), corner + Vector3d(0.0, sy * 0.9 * s, 0.85 * h), stone));
      out.push_back(box_between(corner + Vector3d(-sx * 1.7 * s, sy * 0.9 * s, 0.0), corner + Vector3d(-sx * 0.3 * s, sy * 1.4 * s, 0.45 * h),
                                moulding));
    }
  out.push_back(box_between(Vector3d(-hw - 0.4 * s, -hd - 0.4 * s, h), Vector3d(hw + 0.4 * s, hd + 0.4 * s, h + 0.6 * s), moulding));
  out.push_back(box_between(Vector3d(-hw + 0.8 * s, -hd + 0.5 * s, h + 0.6 * s), Vector3d(hw - 0.8 * s, hd - 0.5 * s, h + kAtticHeight_m * s),
                            paint(stripes(0.6, 0.4, 0.9 * s, 0.12, kHorizontal))));
  // Steps across the passage's mouths and the keystones.
  for (const double sy : {-1.0, 1.0}) {
    out.push_back(box_between(Vector3d(-kPassageHalfSpan_m * s - 0.6, sy * hd, 0.0), Vector3d(kPassageHalfSpan_m * s + 0.6, sy * (hd + 1.2 * s), 0.18),
                              moulding));
    const double crown = kSpring_m * s + kPassageHalfSpan_m * s;
    out.push_back(box_between(Vector3d(-0.5 * s, sy * hd, crown - 0.3 * s), Vector3d(0.5 * s, sy * (hd + 0.25 * s), crown + 1.0 * s), moulding));
  }
}

void add_tree(std::vector<Primitive>& out, double x, double y, double size) {
  out.push_back(cylinder(x, y, 0.0, 3.0 * size, 0.25 * size, paint(stripes(0.28, 0.2, 0.15, 0.05))));
  out.push_back(ellipsoid(Vector3d(x, y, 5.2 * size), Vector3d(3.0, 3.0, 2.6) * size, paint(uniform(0.3), Material::kFoliage)));
}

// The asymmetric surroundings: trees, lamp posts on the facade's side, the facade, benches.
void add_surroundings(std::vector<Primitive>& out, const MonumentLayout& m) {
  for (const auto& [x, y, size] : std::vector<std::tuple<double, double, double>>{
           {-18, -12, 1.0}, {-22, 9, 1.2}, {15, -20, 0.9}, {20, 14, 1.1}, {-8, 30, 1.0}, {30, -4, 1.2}, {-35, -25, 1.1}, {10, 38, 1.0}})
    add_tree(out, x + m.tree_shift_m.x(), y + m.tree_shift_m.y(), size);
  const double side = m.facade_west ? -1.0 : 1.0;
  for (const double y : {-14.0, -4.0, 6.0, 16.0}) {
    out.push_back(cylinder(side * 12.0, y, 0.0, 5.0, 0.09, paint(uniform(0.3))));
    out.push_back(ellipsoid(Vector3d(side * 12.0, y, 5.25), Vector3d(0.25, 0.25, 0.25), paint(uniform(0.85))));
  }
  for (const double y : {-9.0, 11.0})
    out.push_back(box_between(Vector3d(side * 9.0 - 0.25, y - 0.9, 0.0), Vector3d(side * 9.0 + 0.25, y + 0.9, 0.45), paint(uniform(0.45))));

  // A 90 m facade with four storeys of windows and rooms behind the glass, facing the gate.
  const double fx = m.facade_x_m();
  WallSpec facade{Vector3d(fx, side * -45.0, 0.0), side * Vector3d::UnitY(), -side * Vector3d::UnitX(), 90.0, 16.0, 0.25, 4.0,
                  paint(stripes(0.42, 0.62, 4.0, 0.35, kHorizontal)), {}};
  for (int i = 0; i < 15; ++i)
    for (const double sill : {1.0, 5.0, 9.0, 13.0}) {
      const double u = 3.0 + 6.0 * i;
      facade.openings.push_back({u - 0.9, u + 0.9, sill, sill + 2.2});
    }
  add_wall(out, facade);
}

}  // namespace

Scene make_monument_scene(int layout) {
  LayoutDice dice("monument", layout);
  MonumentLayout m;
  m.scale = dice.scale(kMaxScale);
  m.station_distance_m = 25.0 * dice.scale(kMaxScale);
  m.tree_shift_m = {dice.shift(3.0), dice.shift(3.0)};
  m.facade_west = dice.flip();

  Scene scene = empty_scene("monument", layout,
                            "city gate on a plaza, symmetric front to back; trees, lamps and a facade on one side break it", 100.0);
  scene.primitives.push_back(rect(Vector3d(-kGroundHalf_m, -kGroundHalf_m, 0.0), Vector3d::UnitX(), Vector3d::UnitY(),
                                  2.0 * kGroundHalf_m, 2.0 * kGroundHalf_m, paint(checker(0.45, 0.35, 1.5, 0.08))));
  add_gate(scene.primitives, m.scale);
  add_surroundings(scene.primitives, m);

  const double d = m.station_distance_m, away = m.facade_west ? 1.0 : -1.0;
  auto at = [&](double x, double y) { return Vector3d(x + dice.shift(2.0), y + dice.shift(2.0), kScannerHeight_m); };
  scene.stations = {
      {at(3.0, -d), "in front (south) of the gate, facing the passage", {}},
      {at(-3.0, d), "behind (north of) the gate: the half-turn twin of station 0 (hard pair: ~40 % overlap)", {}},
      {at(away * d, -4.0), "beside the gate, on the side away from the facade", {}},
      {at(away * 0.6 * d, -0.8 * d), "in front, to the side, between station 0 and station 2", {}},
  };
  return scene;
}

}  // namespace k4reg::sim
