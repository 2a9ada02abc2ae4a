// The scenes that make registration hard (hall, corridor, monument, courtyard, object): neighbouring
// stations overlap, each scene has the symmetry that makes it hard and only its few details break it,
// the object range scanner's views, and the layouts (variants) of the scenes.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <string>
#include <tuple>
#include <vector>

#include "error_code_of.h"
#include "k4reg/util/error.h"
#include "scene_test_support.h"
#include "sim/bvh.h"
#include "sim/scanner.h"
#include "sim/scene.h"

namespace k4reg::sim {
namespace {

using Eigen::Vector3d;
using Map = std::function<Vector3d(const Vector3d&)>;

constexpr double kOnSurface_m = 0.001;  // noise-free points and their images must lie this close to a surface

ScanParams noise_free(std::size_t points) {
  ScanParams p = params_with(points);
  p.noise_m = 0.0;
  return p;
}

Eigen::AlignedBox3d bounds_of(const std::vector<Primitive>& primitives) {
  Eigen::AlignedBox3d box;
  for (const auto& p : primitives) box.extend(bounds(p.shape));
  return box;
}

// Share of `station`'s noise-free scan of `scene` that `map` sends onto the surfaces of `image_scene`,
// seen from the mapped station: 1 if the map is a symmetry of what the scan saw.
double share_mapped_onto(const Scene& scene, int station, const Map& map, const Scene& image_scene, std::size_t points = 60000) {
  const auto scan = in_scene_frame(simulate_scan(scene, station, noise_free(points)));
  std::vector<Vector3d> images;
  images.reserve(scan.size());
  for (const auto& p : scan) images.push_back(map(p));
  const SceneIndex index(image_scene.primitives_seen_from(station));
  return share_on_visible_surfaces(index, map(scene.stations[station].position_m), images, kOnSurface_m);
}

Scene without(const Scene& scene, const std::function<bool(const Primitive&)>& drop) {
  Scene kept = scene;
  kept.primitives.clear();
  for (const auto& p : scene.primitives)
    if (!drop(p)) kept.primitives.push_back(p);
  return kept;
}

// The hall's partition: the one free-standing box 2.5 m high and ~4 m long.
bool is_partition(const Primitive& p) {
  if (!std::holds_alternative<Box>(p.shape)) return false;
  const Eigen::AlignedBox3d b = bounds(p.shape);
  const Vector3d size = b.sizes();
  return std::abs(b.min().z()) < 1e-9 && std::abs(size.z() - 2.5) < 1e-6 && std::max(size.x(), size.y()) > 3.5 &&
         std::min(size.x(), size.y()) < 0.2;
}

TEST(Scenes, NeighbouringStationsOverlapInTheSceneFrame) {
  // Share of the first scan's 0.5 m voxels (object: 5 mm) that the second also occupies, at 100 k
  // points (object: its default 40 k). Measured at layout 0: hall 0-1 0.49 (opposite corners, the
  // partition in between), hall 2-3 0.72, corridor 0-1 0.48 and 1-2 0.44, monument 0-1 0.13 and 0-2
  // 0.11 (sparse at 100 k points; 0.39 for 0-1 at 1.5 M), courtyard 0-1 0.65, object 0-1 0.51.
  for (const auto& [name, a, b, low, high] : std::vector<std::tuple<std::string, int, int, double, double>>{
           {"hall", 0, 1, 0.35, 0.65},     {"hall", 2, 3, 0.55, 0.9},     {"corridor", 0, 1, 0.3, 0.65},
           {"corridor", 1, 2, 0.3, 0.65},  {"monument", 0, 1, 0.07, 0.25}, {"monument", 0, 2, 0.05, 0.2},
           {"courtyard", 0, 1, 0.45, 0.85}, {"object", 0, 1, 0.35, 0.7}}) {
    const Scene scene = make_scene(name);
    const std::size_t points = std::min<std::size_t>(100000, scene.default_points);
    const double voxel_m = scene.intensity ? 0.5 : 0.005;
    const double share = overlap(in_scene_frame(simulate_scan(scene, a, params_with(points))),
                                 in_scene_frame(simulate_scan(scene, b, params_with(points))), voxel_m);
    EXPECT_GT(share, low) << name << " " << a << "-" << b;
    EXPECT_LT(share, high) << name << " " << a << "-" << b;
  }
}

TEST(Scenes, HallIsMirrorSymmetricExceptThePartition) {
  for (const int layout : {0, 3}) {
    const Scene hall = make_scene("hall", layout);
    int partitions = 0;
    for (const auto& p : hall.primitives) partitions += is_partition(p);
    ASSERT_EQ(partitions, 1) << "layout " << layout;
    const Scene shell = without(hall, is_partition);
    const Vector3d center = bounds_of(shell.primitives).center();
    const Map mirror_x = [&](const Vector3d& p) { return Vector3d(2.0 * center.x() - p.x(), p.y(), p.z()); };
    const Map half_turn = [&](const Vector3d& p) { return Vector3d(2.0 * center.x() - p.x(), 2.0 * center.y() - p.y(), p.z()); };
    // Without the partition the mirror image of everything station 0 sees is in the hall (all but the
    // door handles), and so is its half turn.
    EXPECT_GT(share_mapped_onto(shell, 0, mirror_x, shell), 0.99) << "layout " << layout;
    EXPECT_GT(share_mapped_onto(shell, 0, half_turn, shell), 0.99) << "layout " << layout;
    // With it, the points on the partition have no mirror image: only the few at its foot, which
    // land on the floor.
    const auto scan = in_scene_frame(simulate_scan(hall, 0, noise_free(60000)));
    Eigen::AlignedBox3d partition_box;
    for (const auto& p : hall.primitives)
      if (is_partition(p)) partition_box = bounds(p.shape);
    partition_box.min().array() -= 0.005;
    partition_box.max().array() += 0.005;
    std::vector<Vector3d> on_partition, mirrored;
    for (const auto& p : scan)
      if (partition_box.contains(p)) on_partition.push_back(p);
    ASSERT_GT(on_partition.size(), 500u) << "station 0 sees the partition, layout " << layout;
    for (const auto& p : on_partition) mirrored.push_back(mirror_x(p));
    const SceneIndex index(hall.primitives);
    EXPECT_LT(share_on_visible_surfaces(index, mirror_x(hall.stations[0].position_m), mirrored, kOnSurface_m), 0.05)
        << "layout " << layout;
  }
}

TEST(Scenes, CorridorRepeatsEveryPeriodAndUnderAHalfTurn) {
  const Scene corridor = make_scene("corridor");
  constexpr double kPeriod_m = 4.0, kLength_m = 40.0, kWidth_m = 2.4, kHeight_m = 3.0;
  const Map shift = [](const Vector3d& p) { return Vector3d(p.x() + kPeriod_m, p.y(), p.z()); };
  const Map off_period = [](const Vector3d& p) { return Vector3d(p.x() + 0.3 * kPeriod_m, p.y(), p.z()); };
  const Map half_turn = [](const Vector3d& p) { return Vector3d(kLength_m - p.x(), kWidth_m - p.y(), p.z()); };
  // The plain walls, floor and ceiling map onto themselves under any shift; the test is on the rest:
  // doors, niches, reveals, lights and the details, seen from the middle station.
  const auto scan = in_scene_frame(simulate_scan(corridor, 1, noise_free(100000)));
  std::vector<Vector3d> relief;
  for (const auto& p : scan)
    if (std::min({std::abs(p.y()), std::abs(p.y() - kWidth_m), std::abs(p.z()), std::abs(p.z() - kHeight_m)}) > 0.01 &&
        std::abs(p.x() - corridor.stations[1].position_m.x()) < 12.0)  // a shift by one period stays inside the corridor
      relief.push_back(p);
  ASSERT_GT(relief.size(), 5000u);
  auto mapped_share = [&](const Map& map) {
    std::vector<Vector3d> images;
    for (const auto& p : relief) images.push_back(map(p));
    return share_on_visible_surfaces(SceneIndex(corridor.primitives), map(corridor.stations[1].position_m), images, kOnSurface_m);
  };
  const double by_period = mapped_share(shift), by_half_turn = mapped_share(half_turn), by_0_3_period = mapped_share(off_period);
  EXPECT_GT(by_period, 0.85);
  EXPECT_LT(by_period, 0.995) << "the details must break the periodicity";
  EXPECT_GT(by_half_turn, 0.85);
  EXPECT_LT(by_half_turn, 0.995) << "the details must break the half-turn symmetry";
  EXPECT_LT(by_0_3_period, 0.6) << "a shift that is not the period must not fit";
}

TEST(Scenes, MonumentGateIsHalfTurnSymmetricButItsSurroundingsAreNot) {
  for (const int layout : {0, 1}) {
    const Scene monument = make_scene("monument", layout);
    // The gate: everything within 11 x 7.5 m of the centre (trees, lamps, benches and the facade lie outside).
    const Eigen::AlignedBox3d gate_zone(Vector3d(-11, -7.5, -1), Vector3d(11, 7.5, 30));
    const auto in_gate = [&](const Primitive& p) { return gate_zone.contains(bounds(p.shape)); };
    const Scene gate = without(monument, [&](const Primitive& p) { return !in_gate(p); });
    ASSERT_GT(gate.primitives.size(), 10u);
    const Map half_turn = [](const Vector3d& p) { return Vector3d(-p.x(), -p.y(), p.z()); };
    EXPECT_GT(share_mapped_onto(gate, 0, half_turn, gate, 30000), 0.99) << "layout " << layout;
    // The surroundings (not the gate, not the flat ground) turned by a half turn mostly land nowhere.
    const auto scan = in_scene_frame(simulate_scan(monument, 0, noise_free(100000)));
    std::vector<Vector3d> turned;
    for (const auto& p : scan)
      if (p.z() > 0.05 && !gate_zone.contains(p)) turned.push_back(half_turn(p));
    ASSERT_GT(turned.size(), 2000u);
    const SceneIndex index(monument.primitives);
    EXPECT_LT(share_on_visible_surfaces(index, half_turn(monument.stations[0].position_m), turned, 0.02), 0.2) << "layout " << layout;
  }
}

TEST(Scenes, ObjectScansAreAimedViewsWithoutIntensity) {
  const Scene object = make_scene("object");
  ASSERT_GE(object.stations.size(), 8u);
  for (const int station : {0, 3, 7}) {
    const Station& where = object.stations[station];
    ASSERT_TRUE(where.look_at_m.has_value());
    const auto scan = simulate_scan(object, station, ScanParams{});  // the scene's defaults: 40 k points, 0.15 mm
    EXPECT_FALSE(scan.cloud.has_intensity());
    EXPECT_TRUE(scan.cloud.intensity.empty());
    EXPECT_NEAR(static_cast<double>(scan.cloud.size()), 40000.0, 6000.0) << station;
    const Vector3d forward = (*where.look_at_m - where.position_m).normalized();
    const double half_diagonal_rad = std::atan(std::sqrt(2.0) * std::tan(0.5 * where.field_of_view_deg * M_PI / 180.0));
    const SceneIndex index(object.primitives);
    for (const auto& p : in_scene_frame(scan)) {
      ASSERT_LT((p - *where.look_at_m).norm(), 0.25) << station;
      const Vector3d ray = (p - where.position_m).normalized();
      ASSERT_LT(std::acos(std::min(1.0, ray.dot(forward))), half_diagonal_rad + 1e-6) << "inside the frustum";
    }
    // Front-facing: every point is on a surface the station sees unoccluded, within 4 sigma.
    EXPECT_GT(share_on_visible_surfaces(index, where.position_m, in_scene_frame(scan), 4.0 * object.default_noise_m), 0.99);
  }
  // The frustum really limits the view: a point behind the statuette's far side is not seen, and a
  // scan from a station aimed away from it is empty but for the few rays the minimum hit fraction casts.
  Scene away = object;
  away.stations[0].look_at_m = away.stations[0].position_m + (away.stations[0].position_m - *object.stations[0].look_at_m);
  EXPECT_EQ(simulate_scan(away, 0, params_with(2000)).cloud.size(), 0u);
}

TEST(Scenes, Object15IsTheStatuetteFromFifteenViewsEvery24Degrees) {
  const Scene ring = make_scene("object15"), object = make_scene("object");
  ASSERT_EQ(ring.stations.size(), 15u);
  EXPECT_EQ(bounds_of(ring.primitives).sizes(), bounds_of(object.primitives).sizes()) << "the same statuette";
  for (std::size_t i = 0; i < ring.stations.size(); ++i) {
    const Vector3d from_centre = ring.stations[i].position_m - *ring.stations[i].look_at_m;
    const double azimuth_deg = std::atan2(from_centre.y(), from_centre.x()) * 180.0 / M_PI;
    EXPECT_NEAR(std::remainder(azimuth_deg - 24.0 * static_cast<double>(i), 360.0), 0.0, 1e-6) << i;
  }
  // Closer neighbours share more of the statuette than the ten views' do (object 0-1: 0.51).
  const auto scan = [](const Scene& scene, int station) { return in_scene_frame(simulate_scan(scene, station, params_with(40000))); };
  EXPECT_GT(overlap(scan(ring, 0), scan(ring, 1), 0.005), overlap(scan(object, 0), scan(object, 1), 0.005));
  // Its layouts draw their own dice: object15's layout 3 is not object's with five more views.
  EXPECT_NE(make_scene("object15", 3).stations[0].position_m, make_scene("object", 3).stations[0].position_m);
}

std::uint64_t checksum(const SimulatedScan& scan) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  auto add = [&](const void* data, std::size_t bytes) {
    const auto* c = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < bytes; ++i) h = (h ^ c[i]) * 0x100000001b3ULL;
  };
  add(scan.cloud.points.data(), scan.cloud.points.size() * sizeof(Eigen::Vector3f));
  add(scan.cloud.intensity.data(), scan.cloud.intensity.size() * sizeof(float));
  add(scan.scan_to_scene.data(), sizeof(Eigen::Matrix4d));
  return h;
}

TEST(Scenes, LayoutsAreReproducibleDistinctAndLeaveTheOldScenesAlone) {
  for (const auto& name : {"hall", "corridor", "monument", "courtyard", "object", "object15"}) {
    const Scene a = make_scene(name, 2), b = make_scene(name, 2), c = make_scene(name, 5), canonical = make_scene(name);
    ASSERT_EQ(a.stations.size(), canonical.stations.size()) << name;
    const std::size_t points = std::min<std::size_t>(20000, a.default_points);
    EXPECT_EQ(checksum(simulate_scan(a, 0, params_with(points))), checksum(simulate_scan(b, 0, params_with(points)))) << name;
    EXPECT_NE(checksum(simulate_scan(a, 0, params_with(points))), checksum(simulate_scan(c, 0, params_with(points)))) << name;
    EXPECT_NE(checksum(simulate_scan(a, 0, params_with(points))), checksum(simulate_scan(canonical, 0, params_with(points)))) << name;
    EXPECT_GT((a.stations[0].position_m - canonical.stations[0].position_m).norm(), 1e-3) << name << ": stations move";
    EXPECT_NE(bounds_of(a.primitives).sizes(), bounds_of(canonical.primitives).sizes()) << name << ": dimensions change";
  }
  // lab at layout 0 is the scene the benchmarks were measured on: this checksum of its scan was taken
  // with the simulator of 01ab4aa, before layouts and aimed stations existed (Release build, x86-64).
  EXPECT_EQ(checksum(simulate_scan(make_scene("lab", 0), 0, params_with(20000))), 0xd02dc60e40a0bd96ULL);
  EXPECT_EQ(test::error_code_of([] { make_scene("lab", 1); }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(test::error_code_of([] { make_scene("arch", 3); }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(test::error_code_of([] { make_scene("hall", -1); }), ErrorCode::kInvalidArgument);
  Scene bad = make_scene("object");
  bad.stations[0].field_of_view_deg = 0.0;
  EXPECT_EQ(test::error_code_of([&] { simulate_scan(bad, 0, ScanParams{}); }), ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace k4reg::sim
