// Building blocks for the scene catalogue (internal to the simulator): shorthand constructors for the
// primitives and walls with window and door openings.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "sim/primitives.h"
#include "sim/scene.h"

namespace k4reg::sim {

Surface paint(const Pattern& pattern, Material material = Material::kOpaque);

// Axis-aligned box between two corners.
Primitive box_between(const Eigen::Vector3d& min_m, const Eigen::Vector3d& max_m, const Surface& surface);
// Box rotated by yaw_rad about the vertical through its centre.
Primitive box_yawed(const Eigen::Vector3d& center_m, const Eigen::Vector3d& half_size_m, double yaw_rad,
                    const Surface& surface);
Primitive rect(const Eigen::Vector3d& corner_m, const Eigen::Vector3d& u_axis, const Eigen::Vector3d& v_axis,
               double u_size_m, double v_size_m, const Surface& surface);
Primitive cylinder(double x_m, double y_m, double z_min_m, double z_max_m, double radius_m, const Surface& surface);
Primitive ellipsoid(const Eigen::Vector3d& center_m, const Eigen::Vector3d& radii_m, const Surface& surface);

// A rectangular hole in a wall, in wall coordinates (u along the wall from its start, v up from its foot).
struct Opening {
  double u_min_m, u_max_m, v_min_m, v_max_m;
  bool door = false;  // doors get an opaque leaf and a handle, windows a glass pane and a sill
};

// A vertical wall seen from its inner side. Its pattern uses wall coordinates, so zones (posters)
// can be placed on it independently of how the openings cut it into pieces.
struct WallSpec {
  Eigen::Vector3d start_m;  // foot of the wall's start
  Eigen::Vector3d along;    // unit, horizontal
  Eigen::Vector3d inward;   // unit, horizontal, towards the viewer side
  double length_m = 1.0, height_m = 1.0;
  double thickness_m = 0.3;       // depth of the window and door reveals
  double interior_depth_m = 0.0;  // > 0: a dark back plane this far behind (rooms seen through the glass)
  Surface surface;
  std::vector<Opening> openings;  // openings sharing a u range are stacked (storeys of a facade)
};

void add_wall(std::vector<Primitive>& out, const WallSpec& wall);

Scene make_lab_scene();
Scene make_arch_scene();

}  // namespace k4reg::sim
