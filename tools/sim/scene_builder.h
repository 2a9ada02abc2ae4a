// Building blocks for the scene catalogue (internal to the simulator): shorthand constructors for the
// primitives and walls with window and door openings.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
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
  double recess_m = 0.0;  // windows only: > 0 = an open recess this deep behind the wall face, with an
                          // opaque back instead of the pane (a niche; an open doorway with the room behind)
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

// The four walls of the axis-aligned room [0, length] x [0, width] x [0, height], seen from inside, in
// the order south (y = 0), east (x = length), north, west, each starting where the previous one ends.
// A half turn about the room's vertical axis maps south onto north and east onto west with the same
// wall coordinate u, so equal opening lists on opposite walls make a half-turn symmetric shell.
struct RoomSpec {
  double length_m = 1.0, width_m = 1.0, height_m = 1.0;
  double thickness_m = 0.3;
  double interior_depth_m = 0.0;                 // see WallSpec: rooms behind the windows
  std::array<Surface, 4> surfaces;               // south, east, north, west
  std::array<std::vector<Opening>, 4> openings;  // south, east, north, west
};

void add_room_walls(std::vector<Primitive>& out, const RoomSpec& room);

// A scene with its name, layout, description and default range set, to be filled in.
Scene empty_scene(std::string name, int layout, std::string description, double default_max_range_m);

Scene make_lab_scene();
Scene make_arch_scene();
Scene make_hall_scene(int layout);
Scene make_corridor_scene(int layout);
Scene make_monument_scene(int layout);
Scene make_courtyard_scene(int layout);
// views: 10 ("object") or 15 ("object15").
Scene make_object_scene(int layout, int views);

}  // namespace k4reg::sim
