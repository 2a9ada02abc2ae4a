// The "arch" scene: an outdoor plaza about 100 x 100 m around a Roman triumphal arch, on gently rolling
// ground (a sum of long sine waves), with paths painted on the ground, trees, benches, lamp posts,
// statues, a far facade with three storeys of windows ~70 m north of the arch, a colonnaded building to
// the west, a boundary wall to the south, and hedges that limit what each station sees. People stand
// at different places in every station's scan.
#include <algorithm>
#include <numbers>

#include "sim/random.h"
#include "sim/scene_builder.h"

namespace k4reg::sim {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

constexpr double kHorizontal = std::numbers::pi / 2;  // stripe angle for bands across v (horizontal on walls)
constexpr double kScannerHeight_m = 1.6;              // above the ground at the station

HeightField terrain() {
  HeightField f;
  f.waves = {{0.5, 0.13, 0.0, 0.4}, {0.35, 0.0, 0.19, 1.3}, {0.2, 0.07, 0.11, 2.0}, {0.1, 0.41, -0.37, 0.7}};
  f.min_xy_m = Vector2d(-160.0, -160.0);
  f.max_xy_m = Vector2d(160.0, 160.0);
  return f;
}

Surface ground_paint() {
  Surface s{stripes(0.32, 0.26, 6.0, 3.0), {}, Material::kOpaque};  // lawn with mowing stripes
  s.zones = {
      PatternZone{Vector2d::Zero(), Vector2d(1.5, 0.0), 28.0, uniform(0.5)},               // ring path
      PatternZone{Vector2d::Zero(), Vector2d(2.0, 75.0), 0.0, uniform(0.55)},              // north-south path
      PatternZone{Vector2d::Zero(), Vector2d(75.0, 1.5), 0.0, uniform(0.52)},              // east-west path
      PatternZone{Vector2d::Zero(), Vector2d(14.0, 10.0), 0.0, checker(0.5, 0.4, 1.0, 0.06)},  // paved plaza
  };
  return s;
}

void add_arch(std::vector<Primitive>& out, double z0) {
  const Surface stone = paint(bricks(0.55, 0.35, 1.2, 0.6, 0.02, 0.08));
  const Surface moulding = paint(uniform(0.62));
  // Main block 14 x 5 m, 12 m from its buried foot; passage 6 m wide, springing at 6 m, crown at 9 m.
  out.push_back(Primitive{ArchBlock{Box{Vector3d(0, 0, z0 + 4.0), Eigen::Matrix3d::Identity(), Vector3d(7.0, 2.5, 6.0)}, 3.0, 2.0}, stone});
  out.push_back(box_between(Vector3d(-7.4, -2.9, z0 + 10.0), Vector3d(7.4, 2.9, z0 + 10.5), moulding));
  out.push_back(box_between(Vector3d(-6.8, -2.3, z0 + 10.5), Vector3d(6.8, 2.3, z0 + 14.3), stone));
  out.push_back(box_between(Vector3d(-7.1, -2.6, z0 + 14.3), Vector3d(7.1, 2.6, z0 + 14.7), moulding));
  // Inscriptions on the attic: different line spacing on the two faces.
  const Vector3d x = Vector3d::UnitX(), z = Vector3d::UnitZ();
  out.push_back(rect(Vector3d(-4.0, -2.31, z0 + 11.2), x, z, 8.0, 2.4, paint(stripes(0.75, 0.2, 0.4, 0.15, kHorizontal))));
  out.push_back(rect(Vector3d(-4.0, 2.31, z0 + 11.2), x, z, 8.0, 2.4, paint(stripes(0.75, 0.2, 0.6, 0.3, kHorizontal))));
  // Fluted engaged columns on both faces and stepped plinths under the piers.
  for (const double cx : {-6.2, -3.8, 3.8, 6.2})
    for (const double cy : {-2.65, 2.65}) out.push_back(cylinder(cx, cy, z0 + 0.7, z0 + 9.6, 0.45, paint(stripes(0.62, 0.48, 0.25, 0.08))));
  for (const double side : {-1.0, 1.0}) {
    out.push_back(box_between(Vector3d(side * 2.7, -3.4, z0 - 2.0), Vector3d(side * 7.6, 3.4, z0 + 0.35), moulding));
    out.push_back(box_between(Vector3d(side * 2.85, -3.1, z0 - 2.0), Vector3d(side * 7.3, 3.1, z0 + 0.7), moulding));
  }
}

void add_tree(std::vector<Primitive>& out, const HeightField& f, double x, double y, double size) {
  const double g = f.height(x, y);
  out.push_back(cylinder(x, y, g - 0.5, g + 3.2 * size, 0.22 * size, paint(stripes(0.28, 0.2, 0.15, 0.05))));
  out.push_back(ellipsoid(Vector3d(x, y, g + 5.4 * size), Vector3d(2.8, 2.8, 2.5) * size, paint(uniform(0.3), Material::kFoliage)));
}

void add_far_buildings(std::vector<Primitive>& out, const HeightField& f) {
  // North facade at y = 70: 18 m high from its buried foot at z = -2, eight window columns, three
  // storeys, a central door; light string courses at every sill; rooms behind the glass.
  WallSpec facade{Vector3d(-45.0, 70.0, -2.0), Vector3d::UnitX(), -Vector3d::UnitY(), 90.0, 18.0, 0.25, 4.0,
                  paint(stripes(0.4, 0.62, 4.0, 0.4, kHorizontal)), {}};
  for (int i = 0; i < 8; ++i)
    for (const double sill : {4.0, 8.0, 12.0}) {
      const double u = 10.0 + 10.0 * i;
      facade.openings.push_back({u - 0.9, u + 0.9, sill, sill + 2.4});
    }
  const double door_v = f.height(0.0, 70.0) + 2.0;
  facade.openings.push_back({43.8, 46.2, door_v, door_v + 2.6, true});
  add_wall(out, facade);
  out.push_back(box_between(Vector3d(-45.5, 69.4, 16.0), Vector3d(45.5, 70.0, 16.6), paint(uniform(0.55))));

  // West: a banded building with a colonnade and a canopy.
  out.push_back(box_between(Vector3d(-72.0, -40.0, -2.0), Vector3d(-62.0, 40.0, 9.0), paint(stripes(0.45, 0.3, 3.0, 1.0, kHorizontal))));
  for (int i = 0; i < 8; ++i) {
    const double y = -35.0 + 10.0 * i;
    out.push_back(cylinder(-60.0, y, f.height(-60.0, y) - 0.5, 7.0, 0.35, paint(uniform(0.6))));
  }
  out.push_back(box_between(Vector3d(-62.0, -40.0, 7.0), Vector3d(-59.3, 40.0, 7.6), paint(uniform(0.5))));

  // South: a boundary wall stepping with the terrain, with a gate of two pillars topped by balls.
  for (int i = 0; i < 10; ++i) {
    const double x0 = -50.0 + 10.0 * i, x1 = x0 + 10.0;
    if (x1 <= -3.0 || x0 >= 3.0) {
      const double top = f.height(0.5 * (x0 + x1), -54.8) + 1.3;
      out.push_back(box_between(Vector3d(x0, -55.0, top - 4.0), Vector3d(x1, -54.6, top), paint(bricks(0.45, 0.6, 0.5, 0.25, 0.02, 0.05))));
    } else {
      for (const double side : {-1.0, 1.0}) {
        const double top = f.height(side * 3.0, -54.8) + 2.6;
        out.push_back(box_between(Vector3d(side * 3.0 - 0.4, -55.2, top - 5.0), Vector3d(side * 3.0 + 0.4, -54.4, top), paint(uniform(0.6))));
        out.push_back(ellipsoid(Vector3d(side * 3.0, -54.8, top + 0.3), Vector3d(0.3, 0.3, 0.3), paint(uniform(0.7))));
      }
    }
  }
  // East: a kiosk with a striped awning and a row of trees.
  const double gk = f.height(42.0, -8.0);
  out.push_back(box_between(Vector3d(40.0, -9.5, gk - 0.5), Vector3d(44.0, -6.5, gk + 3.0), paint(uniform(0.5))));
  out.push_back(box_yawed(Vector3d(39.4, -8.0, gk + 2.6), Vector3d(0.6, 1.6, 0.05), 0.0, paint(stripes(0.8, 0.2, 0.5, 0.25))));
  for (int i = 0; i < 6; ++i) add_tree(out, f, 52.0, -40.0 + 16.0 * i, 1.1);
}

void add_plaza_furniture(std::vector<Primitive>& out, const HeightField& f) {
  for (const auto& [x, y, size] : std::vector<std::tuple<double, double, double>>{
           {-26, 14, 1.0}, {-30, -6, 1.2}, {18, 12, 0.9}, {31, 5, 1.1}, {25, -20, 1.0}, {-24, -22, 1.3},
           {8, 35, 1.0}, {-10, 40, 1.2}, {40, -35, 1.0}, {-42, 30, 1.1}, {-5, -38, 0.9}, {15, -42, 1.2}})
    add_tree(out, f, x, y, size);
  for (const double x : {-13.0, 13.0})
    for (const double y : {-9.0, 9.0}) {
      const double g = f.height(x, y);
      out.push_back(cylinder(x, y, g - 0.3, g + 4.5, 0.08, paint(uniform(0.3))));
      out.push_back(ellipsoid(Vector3d(x, y, g + 4.75), Vector3d(0.25, 0.25, 0.25), paint(uniform(0.85))));
    }
  for (const double x : {-9.0, 9.0})
    for (const double y : {-7.0, 7.0}) {
      const double g = f.height(x, y);
      out.push_back(box_between(Vector3d(x - 0.9, y - 0.25, g - 0.3), Vector3d(x + 0.9, y + 0.25, g + 0.45), paint(uniform(0.45))));
    }
  // Two statues on pedestals, different so that they do not mirror each other.
  const double ga = f.height(-10.0, -5.0), gb = f.height(11.0, 5.0);
  out.push_back(box_between(Vector3d(-10.6, -5.6, ga - 0.3), Vector3d(-9.4, -4.4, ga + 1.6), paint(uniform(0.65))));
  out.push_back(cylinder(-10.0, -5.0, ga + 1.6, ga + 3.0, 0.3, paint(uniform(0.3))));
  out.push_back(ellipsoid(Vector3d(-10.0, -5.0, ga + 3.2), Vector3d(0.15, 0.15, 0.2), paint(uniform(0.3))));
  out.push_back(box_between(Vector3d(10.5, 4.2, gb - 0.3), Vector3d(11.5, 5.8, gb + 1.2), paint(checker(0.7, 0.35, 0.4))));
  out.push_back(ellipsoid(Vector3d(11.0, 5.0, gb + 2.0), Vector3d(0.5, 0.7, 0.8), paint(uniform(0.25))));
}

// Radial hedges between the stations' sectors: each station sees its own sector's ground and objects,
// the plaza near the arch, and what rises above 1.8 m (arch, crowns, buildings).
void add_hedges(std::vector<Primitive>& out, const HeightField& f) {
  const Surface hedge = paint(dots(0.22, 0.12, 0.7, 0.2));
  for (const double azimuth_deg : {-70.0, 20.0, 110.0, 200.0}) {
    const double a = azimuth_deg * std::numbers::pi / 180.0;
    const Vector2d dir(std::cos(a), std::sin(a));
    constexpr double kInner_m = 15.0, kOuter_m = 40.0;
    const Vector2d mid = 0.5 * (kInner_m + kOuter_m) * dir;
    // Sits 1.8 m above the terrain's lowest point along it and reaches 2 m below.
    double low = 1e9;
    for (double r = kInner_m; r <= kOuter_m; r += 1.0) low = std::min(low, f.height(r * dir.x(), r * dir.y()));
    out.push_back(box_yawed(Vector3d(mid.x(), mid.y(), low - 0.1), Vector3d(0.5 * (kOuter_m - kInner_m), 0.4, 1.9), a, hedge));
  }
}

// People stand near fixed anchors, displaced differently for every station (they walk between scans),
// never closer than 3 m to the scanner or inside the arch's footprint.
std::vector<Primitive> people_at(int station, const Vector3d& scanner, const HeightField& f) {
  const std::vector<Vector2d> anchors = {{-6, -12}, {6, -13}, {13, 3}, {-13, -2}, {4, 12}, {-5, 16}, {20, -20}, {-18, 18}};
  std::vector<Primitive> people;
  for (std::size_t k = 0; k < anchors.size(); ++k) {
    RandomStream rng(derive_key(0x7065'6f70'6c65ULL, static_cast<std::uint64_t>(station) * 64 + k));
    Vector2d p = anchors[k];
    for (int attempt = 0; attempt < 32; ++attempt) {
      const double angle = 2.0 * std::numbers::pi * rng.uniform(), radius = 4.0 * std::sqrt(rng.uniform());
      p = anchors[k] + radius * Vector2d(std::cos(angle), std::sin(angle));
      const bool near_scanner = (p - scanner.head<2>()).norm() < 3.0;
      const bool in_arch = std::abs(p.x()) < 8.5 && std::abs(p.y()) < 4.5;
      if (!near_scanner && !in_arch) break;
    }
    const double g = f.height(p.x(), p.y());
    people.push_back(cylinder(p.x(), p.y(), g - 0.1, g + 1.45, 0.2, paint(uniform(0.15 + 0.45 * rng.uniform()))));
    people.push_back(ellipsoid(Vector3d(p.x(), p.y(), g + 1.6), Vector3d(0.1, 0.1, 0.12), paint(uniform(0.35))));
  }
  return people;
}

}  // namespace

Scene make_arch_scene() {
  Scene scene;
  scene.name = "arch";
  scene.description = "outdoor plaza ~100 x 100 m: Roman arch, rolling ground, trees, far facade, people";
  scene.default_max_range_m = 120.0;
  const HeightField ground = terrain();
  scene.primitives.push_back(Primitive{ground, ground_paint()});
  add_arch(scene.primitives, ground.height(0.0, 0.0));
  add_far_buildings(scene.primitives, ground);
  add_plaza_furniture(scene.primitives, ground);
  add_hedges(scene.primitives, ground);

  const std::vector<std::pair<Vector2d, std::string>> stations = {
      {{-10.0, -20.0}, "south-south-west of the arch"},
      {{20.0, -8.0}, "east-south-east of the arch"},
      {{10.0, 20.0}, "north-north-east of the arch"},
      {{-20.0, 8.0}, "west-north-west of the arch"},
  };
  for (std::size_t i = 0; i < stations.size(); ++i) {
    const Vector2d& xy = stations[i].first;
    const Vector3d position(xy.x(), xy.y(), ground.height(xy.x(), xy.y()) + kScannerHeight_m);
    scene.stations.push_back({position, stations[i].second, people_at(static_cast<int>(i), position, ground)});
  }
  return scene;
}

}  // namespace k4reg::sim
