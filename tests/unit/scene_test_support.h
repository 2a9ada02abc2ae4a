// Helpers shared by the simulator's tests: scans in the scene frame, voxel overlap, and whether points
// lie on the surfaces a station sees.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <unordered_set>
#include <vector>

#include "sim/bvh.h"
#include "sim/scanner.h"
#include "sim/scene.h"

namespace k4reg::sim {

inline std::vector<Eigen::Vector3d> in_scene_frame(const SimulatedScan& scan) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(scan.cloud.size());
  for (const auto& p : scan.cloud.points)
    out.push_back(scan.scan_to_scene.topLeftCorner<3, 3>() * p.cast<double>() + scan.scan_to_scene.topRightCorner<3, 1>());
  return out;
}

inline std::unordered_set<std::uint64_t> occupied_voxels(const std::vector<Eigen::Vector3d>& points, double voxel_m) {
  std::unordered_set<std::uint64_t> voxels;
  for (const auto& p : points) {
    const Eigen::Array3d cell = (p / voxel_m).array().floor() + 100000.0;
    voxels.insert((static_cast<std::uint64_t>(cell.x()) << 42) | (static_cast<std::uint64_t>(cell.y()) << 21) |
                  static_cast<std::uint64_t>(cell.z()));
  }
  return voxels;
}

// Share of a's voxels that b also occupies.
inline double overlap(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b, double voxel_m) {
  const auto va = occupied_voxels(a, voxel_m), vb = occupied_voxels(b, voxel_m);
  std::size_t shared = 0;
  for (const auto v : va) shared += vb.count(v);
  return static_cast<double>(shared) / static_cast<double>(va.size());
}

inline ScanParams params_with(std::size_t points, std::uint64_t seed = 1) {
  ScanParams p;
  p.points = points;
  p.seed = seed;
  return p;
}

// For each point: its range from the scanner minus the distance to the nearest scene surface along
// the same beam, among the surfaces up to and including the first opaque one (glass and foliage in
// front of it may return the beam or let it through).
inline std::vector<double> range_residuals(const Scene& scene, int station, const SimulatedScan& scan) {
  const SceneIndex index(scene.primitives_seen_from(station));
  const Eigen::Vector3d origin = scene.stations[station].position_m;
  std::vector<double> residuals;
  for (const auto& p : in_scene_frame(scan)) {
    const double range = (p - origin).norm();
    const Ray ray{origin, (p - origin) / range};
    double residual = 1e9;
    for (auto hit = index.closest_hit(ray, 0.3, 1000.0); hit; hit = index.closest_hit(ray, hit->distance_m + 1e-4, 1000.0)) {
      if (std::abs(range - hit->distance_m) < std::abs(residual)) residual = range - hit->distance_m;
      if (hit->material == Material::kOpaque) break;
    }
    residuals.push_back(residual);
  }
  return residuals;
}

// Share of the points that lie within tolerance_m (along the surface normal) of a surface of `index`
// that a scanner at `origin` sees unoccluded: the geometric test of "this point exists in that scene,
// seen from there".
inline double share_on_visible_surfaces(const SceneIndex& index, const Eigen::Vector3d& origin,
                                        const std::vector<Eigen::Vector3d>& points, double tolerance_m) {
  std::size_t on = 0;
  for (const auto& p : points) {
    const double range = (p - origin).norm();
    const Ray ray{origin, (p - origin) / range};
    for (auto hit = index.closest_hit(ray, 0.05, range + 1.0); hit; hit = index.closest_hit(ray, hit->distance_m + 1e-4, range + 1.0)) {
      if (std::abs(hit->distance_m - range) * std::abs(hit->normal.dot(ray.direction)) <= tolerance_m) {
        ++on;
        break;
      }
      if (hit->material == Material::kOpaque || hit->distance_m > range) break;
    }
  }
  return points.empty() ? 0.0 : static_cast<double>(on) / static_cast<double>(points.size());
}

}  // namespace k4reg::sim
