// What a surface looks like to the laser: a reflectivity pattern over the surface's own (u, v)
// coordinates in metres, optional painted zones on top of it, and a material that decides whether
// the beam returns at all. The patterns give the intensity keypoint detector repeatable blobs and
// corners (posters, checkerboards, stripes, brick courses, floor markings).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace k4reg::sim {

enum class PatternKind {
  kUniform,  // base everywhere
  kStripes,  // parallel stripes of width size_m every period_m, direction angle_rad
  kChecker,  // square cells of period_m alternating base / mark
  kGrid,     // lines of width size_m every period_m in u and v (tiles, ceiling panels)
  kBricks,   // courses of course_m, bricks of period_m offset by half a brick, mortar size_m
  kDots,     // discs of radius size_m on a square lattice of period_m
};

struct Pattern {
  PatternKind kind = PatternKind::kUniform;
  double base = 0.5;          // reflectivity of the background, in [0, 1]
  double mark = 0.5;          // reflectivity of the stripes / odd cells / lines / mortar / dots
  double period_m = 1.0;
  double size_m = 0.1;
  double course_m = 0.5;      // bricks only
  double angle_rad = 0.0;     // stripes only: 0 = stripes run along v (u selects the stripe)
  double tone_jitter = 0.0;   // checker / bricks: each cell's reflectivity varies by up to +- this

  double reflectivity(const Eigen::Vector2d& uv) const;
};

Pattern uniform(double reflectivity);
Pattern stripes(double base, double mark, double period_m, double width_m, double angle_rad = 0.0);
Pattern checker(double base, double mark, double cell_m, double tone_jitter = 0.0);
Pattern grid(double base, double line, double cell_m, double line_width_m);
Pattern bricks(double brick, double mortar, double length_m, double course_m, double mortar_m, double tone_jitter);
Pattern dots(double base, double dot, double spacing_m, double radius_m);

// A region of the (u, v) plane painted with its own pattern: a poster on a wall, a path on the ground.
// The zone's pattern is laid out from the zone's corner (center - half size), so a checkerboard starts
// with a full cell.
struct PatternZone {
  Eigen::Vector2d center_m = Eigen::Vector2d::Zero();
  Eigen::Vector2d half_size_m = Eigen::Vector2d::Zero();  // rectangle; for a ring only x = half width
  double ring_radius_m = 0.0;                             // > 0: an annulus of this mid-line radius
  Pattern pattern;

  bool contains(const Eigen::Vector2d& uv) const;
};

enum class Material {
  kOpaque,   // always returns (unless grazing or too dark)
  kGlass,    // mostly transmits; the few returns are weak and noisy, like real window panes
  kFoliage,  // tree crowns, hedges' tops: half the beams pass between the leaves
};

struct Surface {
  Pattern pattern;
  std::vector<PatternZone> zones;  // later zones paint over earlier ones
  Material material = Material::kOpaque;

  double reflectivity(const Eigen::Vector2d& uv) const;
};

}  // namespace k4reg::sim
