#include "sim/scene_builder.h"

#include <algorithm>
#include <utility>

namespace k4reg::sim {

Scene empty_scene(std::string name, int layout, std::string description, double default_max_range_m) {
  Scene scene;
  scene.name = std::move(name);
  scene.layout = layout;
  scene.description = std::move(description);
  scene.default_max_range_m = default_max_range_m;
  return scene;
}

Surface paint(const Pattern& pattern, Material material) { return Surface{pattern, {}, material}; }

Primitive box_between(const Eigen::Vector3d& min_m, const Eigen::Vector3d& max_m, const Surface& surface) {
  const Eigen::Vector3d lo = min_m.cwiseMin(max_m), hi = min_m.cwiseMax(max_m);
  return Primitive{Box{0.5 * (lo + hi), Eigen::Matrix3d::Identity(), 0.5 * (hi - lo)}, surface};
}

Primitive box_yawed(const Eigen::Vector3d& center_m, const Eigen::Vector3d& half_size_m, double yaw_rad,
                    const Surface& surface) {
  const Eigen::Matrix3d axes = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return Primitive{Box{center_m, axes, half_size_m}, surface};
}

Primitive rect(const Eigen::Vector3d& corner_m, const Eigen::Vector3d& u_axis, const Eigen::Vector3d& v_axis,
               double u_size_m, double v_size_m, const Surface& surface) {
  return Primitive{Rect{corner_m, u_axis, v_axis, u_size_m, v_size_m}, surface};
}

Primitive cylinder(double x_m, double y_m, double z_min_m, double z_max_m, double radius_m, const Surface& surface) {
  return Primitive{Cylinder{{x_m, y_m}, z_min_m, z_max_m, radius_m}, surface};
}

Primitive ellipsoid(const Eigen::Vector3d& center_m, const Eigen::Vector3d& radii_m, const Surface& surface) {
  return Primitive{Ellipsoid{center_m, radii_m}, surface};
}

void add_wall(std::vector<Primitive>& out, const WallSpec& wall) {
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ(), outward = -wall.inward;
  auto at = [&](double u, double v, double depth) { return Eigen::Vector3d(wall.start_m + u * wall.along + v * up + depth * outward); };
  auto piece = [&](double u0, double u1, double v0, double v1) {
    if (u1 - u0 < 1e-9 || v1 - v0 < 1e-9) return;
    Primitive p = rect(at(u0, v0, 0.0), wall.along, up, u1 - u0, v1 - v0, wall.surface);
    std::get<Rect>(p.shape).uv_origin_m = {u0, v0};
    out.push_back(std::move(p));
  };
  const Surface reveal = paint(uniform(wall.surface.pattern.base));
  const double depth = wall.thickness_m;
  auto add_opening = [&](const Opening& o) {
    const double w = o.u_max_m - o.u_min_m, h = o.v_max_m - o.v_min_m;
    out.push_back(rect(at(o.u_min_m, o.v_min_m, 0.0), outward, up, depth, h, reveal));
    out.push_back(rect(at(o.u_max_m, o.v_min_m, 0.0), outward, up, depth, h, reveal));
    out.push_back(rect(at(o.u_min_m, o.v_max_m, 0.0), wall.along, outward, w, depth, reveal));
    if (o.door) {
      const Surface casing = paint(uniform(0.22));
      constexpr double kLeaf_m = 0.08, kCasing_m = 0.08, kProud_m = 0.02;
      out.push_back(rect(at(o.u_min_m, o.v_min_m, kLeaf_m), wall.along, up, w, h, paint(uniform(0.42))));
      out.push_back(box_between(at(o.u_max_m - 0.2, o.v_min_m + 1.0, kLeaf_m), at(o.u_max_m - 0.08, o.v_min_m + 1.05, kLeaf_m - 0.06),
                                paint(uniform(0.8))));
      out.push_back(box_between(at(o.u_min_m - kCasing_m, o.v_min_m, 0.0), at(o.u_min_m, o.v_max_m + kCasing_m, -kProud_m), casing));
      out.push_back(box_between(at(o.u_max_m, o.v_min_m, 0.0), at(o.u_max_m + kCasing_m, o.v_max_m + kCasing_m, -kProud_m), casing));
      out.push_back(box_between(at(o.u_min_m, o.v_max_m, 0.0), at(o.u_max_m, o.v_max_m + kCasing_m, -kProud_m), casing));
    } else {
      out.push_back(rect(at(o.u_min_m, o.v_min_m, 0.0), wall.along, outward, w, depth, reveal));
      if (o.recess_m > 0.0)
        out.push_back(rect(at(o.u_min_m, o.v_min_m, o.recess_m), wall.along, up, w, h, paint(uniform(0.3))));
      else
        out.push_back(rect(at(o.u_min_m, o.v_min_m, 0.6 * depth), wall.along, up, w, h, paint(uniform(0.1), Material::kGlass)));
    }
  };

  std::vector<Opening> openings = wall.openings;
  std::sort(openings.begin(), openings.end(), [](const Opening& a, const Opening& b) {
    return std::pair(a.u_min_m, a.v_min_m) < std::pair(b.u_min_m, b.v_min_m);
  });
  // Cut the wall into full-height pieces between columns of openings and pieces above, between and
  // below the openings of each column.
  double u = 0.0;
  for (std::size_t i = 0; i < openings.size();) {
    const double u0 = openings[i].u_min_m, u1 = openings[i].u_max_m;
    piece(u, u0, 0.0, wall.height_m);
    double v = 0.0;
    for (; i < openings.size() && openings[i].u_min_m == u0; ++i) {
      piece(u0, u1, v, openings[i].v_min_m);
      v = openings[i].v_max_m;
      add_opening(openings[i]);
    }
    piece(u0, u1, v, wall.height_m);
    u = u1;
  }
  piece(u, wall.length_m, 0.0, wall.height_m);
  if (wall.interior_depth_m > 0.0)
    out.push_back(rect(at(0.0, 0.0, wall.interior_depth_m), wall.along, up, wall.length_m, wall.height_m,
                       paint(uniform(0.12))));
}

void add_room_walls(std::vector<Primitive>& out, const RoomSpec& room) {
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY();
  const double l = room.length_m, w = room.width_m;
  const std::array<Eigen::Vector3d, 4> starts = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(l, 0, 0), Eigen::Vector3d(l, w, 0),
                                                 Eigen::Vector3d(0, w, 0)};
  const std::array<Eigen::Vector3d, 4> alongs = {x, y, -x, -y};
  const std::array<double, 4> lengths = {l, w, l, w};
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d inward = Eigen::Vector3d::UnitZ().cross(alongs[i]);  // left of the walking direction
    add_wall(out, WallSpec{starts[i], alongs[i], inward, lengths[i], room.height_m, room.thickness_m, room.interior_depth_m,
                           room.surfaces[i], room.openings[i]});
  }
}

}  // namespace k4reg::sim
