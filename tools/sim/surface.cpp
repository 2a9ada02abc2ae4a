#include "sim/surface.h"

#include <algorithm>
#include <cmath>

#include "sim/random.h"

namespace k4reg::sim {
namespace {

// Position of x inside its period, in [0, period).
double wrap(double x, double period) { return x - period * std::floor(x / period); }

// A fixed per-cell tone offset in [-jitter, +jitter]: hashed from the cell index, so it never changes.
double cell_tone(double jitter, double i, double j) {
  if (jitter == 0.0) return 0.0;
  const auto key = derive_key(static_cast<std::uint64_t>(static_cast<std::int64_t>(i)),
                              static_cast<std::uint64_t>(static_cast<std::int64_t>(j)));
  return jitter * (2.0 * RandomStream(key).uniform() - 1.0);
}

}  // namespace

double Pattern::reflectivity(const Eigen::Vector2d& uv) const {
  double r = base;
  switch (kind) {
    case PatternKind::kUniform:
      break;
    case PatternKind::kStripes: {
      const double s = uv.x() * std::cos(angle_rad) + uv.y() * std::sin(angle_rad);
      if (wrap(s, period_m) < size_m) r = mark;
      break;
    }
    case PatternKind::kChecker: {
      const double i = std::floor(uv.x() / period_m), j = std::floor(uv.y() / period_m);
      r = (static_cast<std::int64_t>(i + j) % 2 == 0 ? base : mark) + cell_tone(tone_jitter, i, j);
      break;
    }
    case PatternKind::kGrid:
      if (wrap(uv.x(), period_m) < size_m || wrap(uv.y(), period_m) < size_m) r = mark;
      break;
    case PatternKind::kBricks: {
      const double row = std::floor(uv.y() / course_m);
      const double shifted = uv.x() + (static_cast<std::int64_t>(row) % 2 == 0 ? 0.0 : 0.5 * period_m);
      const double col = std::floor(shifted / period_m);
      if (wrap(uv.y(), course_m) < size_m || wrap(shifted, period_m) < size_m)
        r = mark;
      else
        r = base + cell_tone(tone_jitter, col, row);
      break;
    }
    case PatternKind::kDots: {
      const double du = wrap(uv.x(), period_m) - 0.5 * period_m, dv = wrap(uv.y(), period_m) - 0.5 * period_m;
      if (du * du + dv * dv < size_m * size_m) r = mark;
      break;
    }
  }
  return std::clamp(r, 0.0, 1.0);
}

Pattern uniform(double reflectivity) { return Pattern{.base = reflectivity, .mark = reflectivity}; }

Pattern stripes(double base, double mark, double period_m, double width_m, double angle_rad) {
  return Pattern{.kind = PatternKind::kStripes, .base = base, .mark = mark, .period_m = period_m, .size_m = width_m,
                 .angle_rad = angle_rad};
}

Pattern checker(double base, double mark, double cell_m, double tone_jitter) {
  return Pattern{.kind = PatternKind::kChecker, .base = base, .mark = mark, .period_m = cell_m,
                 .tone_jitter = tone_jitter};
}

Pattern grid(double base, double line, double cell_m, double line_width_m) {
  return Pattern{.kind = PatternKind::kGrid, .base = base, .mark = line, .period_m = cell_m, .size_m = line_width_m};
}

Pattern bricks(double brick, double mortar, double length_m, double course_m, double mortar_m, double tone_jitter) {
  return Pattern{.kind = PatternKind::kBricks, .base = brick, .mark = mortar, .period_m = length_m,
                 .size_m = mortar_m, .course_m = course_m, .tone_jitter = tone_jitter};
}

Pattern dots(double base, double dot, double spacing_m, double radius_m) {
  return Pattern{.kind = PatternKind::kDots, .base = base, .mark = dot, .period_m = spacing_m, .size_m = radius_m};
}

bool PatternZone::contains(const Eigen::Vector2d& uv) const {
  if (ring_radius_m > 0.0) return std::abs((uv - center_m).norm() - ring_radius_m) < half_size_m.x();
  return ((uv - center_m).cwiseAbs().array() < half_size_m.array()).all();
}

double Surface::reflectivity(const Eigen::Vector2d& uv) const {
  for (auto zone = zones.rbegin(); zone != zones.rend(); ++zone)
    if (zone->contains(uv)) return zone->pattern.reflectivity(uv - zone->center_m + zone->half_size_m);
  return pattern.reflectivity(uv);
}

}  // namespace k4reg::sim
