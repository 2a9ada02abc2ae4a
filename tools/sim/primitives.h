// Analytic shapes of the simulated scenes and their ray intersections. Each intersection returns the
// distance along the ray, the normal facing the ray, and the (u, v) surface coordinates in metres at
// which the surface's reflectivity pattern is evaluated. Ray origins are outside the solids (the
// scanner stands in free space); a ray that continues after passing through glass or foliage starts
// just behind that surface.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <variant>
#include <vector>

#include "sim/surface.h"

namespace k4reg::sim {

struct Ray {
  Eigen::Vector3d origin;
  Eigen::Vector3d direction;  // unit length
};

struct ShapeHit {
  double distance_m = 0.0;
  Eigen::Vector3d normal;  // unit, facing the ray (normal . direction <= 0)
  Eigen::Vector2d uv_m;    // surface coordinates for the pattern
};

// A planar rectangle, visible from both sides: walls, posters, glass panes.
struct Rect {
  Eigen::Vector3d corner_m;
  Eigen::Vector3d u_axis, v_axis;  // unit and orthogonal; normal = u x v
  double u_size_m = 1.0, v_size_m = 1.0;
  Eigen::Vector2d uv_origin_m = Eigen::Vector2d::Zero();  // uv of the corner: pieces of one wall share a pattern
};

// An oriented box; uv on each face are the two in-face local coordinates from the box's minimum corner.
struct Box {
  Eigen::Vector3d center_m;
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  // columns: the box's x, y, z axes in the scene
  Eigen::Vector3d half_size_m;
};

// A vertical capped cylinder: pillars, trunks, columns, people.
struct Cylinder {
  Eigen::Vector2d center_xy_m;
  double z_min_m = 0.0, z_max_m = 1.0;
  double radius_m = 0.5;
};

// An axis-aligned ellipsoid: tree crowns, heads, lamps.
struct Ellipsoid {
  Eigen::Vector3d center_m;
  Eigen::Vector3d radii_m;
};

// A box with a round-arched passage through it along its local y axis: straight sides of half width
// half_span_m up to spring_z_m (local z, from the box centre), then a half circle of that radius.
struct ArchBlock {
  Box block;
  double half_span_m = 1.0;
  double spring_z_m = 0.0;
};

// Terrain z = base_z_m + sum of a sin(kx x + ky y + phase) over a rectangle; uv = (x, y).
struct HeightField {
  struct Wave {
    double amplitude_m, kx, ky, phase;  // wave numbers in rad/m
  };
  double base_z_m = 0.0;
  std::vector<Wave> waves;
  Eigen::Vector2d min_xy_m, max_xy_m;

  double height(double x, double y) const;
  Eigen::Vector3d normal(double x, double y) const;  // upward unit normal
};

using Shape = std::variant<Rect, Box, Cylinder, Ellipsoid, ArchBlock, HeightField>;

struct Primitive {
  Shape shape;
  Surface surface;
};

// The nearest intersection with distance in [t_min, t_max], if any.
std::optional<ShapeHit> intersect(const Shape& shape, const Ray& ray, double t_min, double t_max);

// Axis-aligned bounds in the scene frame (for the BVH).
Eigen::AlignedBox3d bounds(const Shape& shape);

}  // namespace k4reg::sim
