#include "sim/primitives.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

namespace k4reg::sim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kTiny = 1e-15;  // direction components below this count as parallel

Eigen::Vector3d facing(const Eigen::Vector3d& n, const Eigen::Vector3d& direction) {
  return n.dot(direction) > 0.0 ? Eigen::Vector3d(-n) : n;
}

// Parameter interval of the ray inside an axis-aligned box [-half, half] in local coordinates; the
// axes whose slabs bound the entry and the exit.
struct SlabInterval {
  double t_in = -kInf, t_out = kInf;
  int axis_in = 0, axis_out = 0;
  bool empty() const { return t_in > t_out; }
};

SlabInterval slab_interval(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& half) {
  SlabInterval s;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(d[i]) < kTiny) {
      if (std::abs(o[i]) > half[i]) return SlabInterval{kInf, -kInf, 0, 0};
      continue;
    }
    double t0 = (-half[i] - o[i]) / d[i], t1 = (half[i] - o[i]) / d[i];
    if (t0 > t1) std::swap(t0, t1);
    if (t0 > s.t_in) s.t_in = t0, s.axis_in = i;
    if (t1 < s.t_out) s.t_out = t1, s.axis_out = i;
  }
  return s;
}

// uv on the box face perpendicular to axis: the two other local coordinates from the minimum corner.
Eigen::Vector2d box_face_uv(const Eigen::Vector3d& p_local, const Eigen::Vector3d& half, int axis) {
  const Eigen::Vector3d q = p_local + half;
  if (axis == 0) return {q.y(), q.z()};
  if (axis == 1) return {q.x(), q.z()};
  return {q.x(), q.y()};
}

// Hit on the face perpendicular to `axis`; o and d are the ray in box coordinates.
ShapeHit box_face_hit(const Box& box, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t, int axis) {
  Eigen::Vector3d n_local = Eigen::Vector3d::Zero();
  n_local[axis] = d[axis] > 0.0 ? -1.0 : 1.0;  // the face looking back at the ray
  return ShapeHit{t, box.axes * n_local, box_face_uv(o + t * d, box.half_size_m, axis)};
}

const Box& block_of(const Box& box) { return box; }
const Box& block_of(const ArchBlock& arch) { return arch.block; }

std::optional<ShapeHit> intersect_rect(const Rect& r, const Ray& ray, double t_min, double t_max) {
  const Eigen::Vector3d n = r.u_axis.cross(r.v_axis);
  const double denom = ray.direction.dot(n);
  if (std::abs(denom) < kTiny) return std::nullopt;
  const double t = (r.corner_m - ray.origin).dot(n) / denom;
  if (!(t >= t_min && t <= t_max)) return std::nullopt;
  const Eigen::Vector3d q = ray.origin + t * ray.direction - r.corner_m;
  const double a = q.dot(r.u_axis), b = q.dot(r.v_axis);
  if (a < 0.0 || a > r.u_size_m || b < 0.0 || b > r.v_size_m) return std::nullopt;
  return ShapeHit{t, denom < 0.0 ? n : Eigen::Vector3d(-n), r.uv_origin_m + Eigen::Vector2d(a, b)};
}

std::optional<ShapeHit> intersect_box(const Box& box, const Ray& ray, double t_min, double t_max) {
  const Eigen::Vector3d o = box.axes.transpose() * (ray.origin - box.center_m);
  const Eigen::Vector3d d = box.axes.transpose() * ray.direction;
  const SlabInterval s = slab_interval(o, d, box.half_size_m);
  if (s.empty()) return std::nullopt;
  if (s.t_in >= t_min && s.t_in <= t_max) return box_face_hit(box, o, d, s.t_in, s.axis_in);
  if (s.t_in < t_min && s.t_out >= t_min && s.t_out <= t_max)  // started inside: the far wall
    return box_face_hit(box, o, d, s.t_out, s.axis_out);
  return std::nullopt;
}

std::optional<ShapeHit> intersect_cylinder(const Cylinder& c, const Ray& ray, double t_min, double t_max) {
  const Eigen::Vector3d& o = ray.origin;
  const Eigen::Vector3d& d = ray.direction;
  const double ox = o.x() - c.center_xy_m.x(), oy = o.y() - c.center_xy_m.y();
  std::optional<ShapeHit> best;
  auto consider = [&](double t, const Eigen::Vector3d& n, const Eigen::Vector2d& uv) {
    if (t >= t_min && t <= t_max && (!best || t < best->distance_m)) best = ShapeHit{t, facing(n, d), uv};
  };
  const double a = d.x() * d.x() + d.y() * d.y();
  if (a > kTiny) {
    const double b = ox * d.x() + oy * d.y();
    const double disc = b * b - a * (ox * ox + oy * oy - c.radius_m * c.radius_m);
    if (disc >= 0.0) {
      const double sq = std::sqrt(disc);
      for (const double t : {(-b - sq) / a, (-b + sq) / a}) {
        const double z = o.z() + t * d.z();
        if (z < c.z_min_m || z > c.z_max_m) continue;
        const double px = ox + t * d.x(), py = oy + t * d.y();
        consider(t, Eigen::Vector3d(px, py, 0.0) / c.radius_m,
                 {c.radius_m * std::atan2(py, px), z - c.z_min_m});
      }
    }
  }
  if (std::abs(d.z()) > kTiny) {
    for (const double z_cap : {c.z_min_m, c.z_max_m}) {
      const double t = (z_cap - o.z()) / d.z();
      const double px = ox + t * d.x(), py = oy + t * d.y();
      if (px * px + py * py <= c.radius_m * c.radius_m)
        consider(t, Eigen::Vector3d(0.0, 0.0, 1.0), {px + c.radius_m, py + c.radius_m});
    }
  }
  return best;
}

std::optional<ShapeHit> intersect_ellipsoid(const Ellipsoid& e, const Ray& ray, double t_min, double t_max) {
  // In coordinates scaled by the radii the ellipsoid is the unit sphere; t is unchanged.
  const Eigen::Vector3d o = (ray.origin - e.center_m).cwiseQuotient(e.radii_m);
  const Eigen::Vector3d d = ray.direction.cwiseQuotient(e.radii_m);
  const double a = d.squaredNorm(), b = o.dot(d), c = o.squaredNorm() - 1.0;
  const double disc = b * b - a * c;
  if (disc < 0.0) return std::nullopt;
  const double sq = std::sqrt(disc);
  for (const double t : {(-b - sq) / a, (-b + sq) / a}) {
    if (t < t_min || t > t_max) continue;
    const Eigen::Vector3d p = ray.origin + t * ray.direction - e.center_m;
    const Eigen::Vector3d n = p.cwiseQuotient(e.radii_m.cwiseProduct(e.radii_m)).normalized();
    return ShapeHit{t, facing(n, ray.direction), {e.radii_m.x() * std::atan2(p.y(), p.x()), p.z() + e.radii_m.z()}};
  }
  return std::nullopt;
}

// Parameter interval of the ray inside the passage {|x| < r, z < zs} u {x^2 + (z - zs)^2 < r^2}
// (local coordinates). Both parts are convex and so is their union, so the union is one interval.
std::pair<double, double> passage_interval(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double r, double zs) {
  constexpr std::pair<double, double> kEmpty{kInf, -kInf};
  // Straight part: slab |x| < r intersected with half space z < zs.
  std::pair<double, double> straight{-kInf, kInf};
  if (std::abs(d.x()) < kTiny) {
    if (std::abs(o.x()) >= r) straight = kEmpty;
  } else {
    const double t0 = (-r - o.x()) / d.x(), t1 = (r - o.x()) / d.x();
    straight = {std::min(t0, t1), std::max(t0, t1)};
  }
  if (std::abs(d.z()) < kTiny) {
    if (o.z() >= zs) straight = kEmpty;
  } else if (d.z() > 0.0) {
    straight.second = std::min(straight.second, (zs - o.z()) / d.z());
  } else {
    straight.first = std::max(straight.first, (zs - o.z()) / d.z());
  }
  // Round part: infinite cylinder along y.
  std::pair<double, double> round = kEmpty;
  const double a = d.x() * d.x() + d.z() * d.z();
  const double oz = o.z() - zs;
  const double c = o.x() * o.x() + oz * oz - r * r;
  if (a < kTiny) {
    if (c < 0.0) round = {-kInf, kInf};
  } else {
    const double b = o.x() * d.x() + oz * d.z();
    const double disc = b * b - a * c;
    if (disc > 0.0) round = {(-b - std::sqrt(disc)) / a, (-b + std::sqrt(disc)) / a};
  }
  const bool has_straight = straight.first < straight.second, has_round = round.first < round.second;
  if (has_straight && has_round) return {std::min(straight.first, round.first), std::max(straight.second, round.second)};
  if (has_straight) return straight;
  if (has_round) return round;
  return kEmpty;
}

std::optional<ShapeHit> intersect_arch(const ArchBlock& arch, const Ray& ray, double t_min, double t_max) {
  const Box& box = arch.block;
  const Eigen::Vector3d o = box.axes.transpose() * (ray.origin - box.center_m);
  const Eigen::Vector3d d = box.axes.transpose() * ray.direction;
  const SlabInterval s = slab_interval(o, d, box.half_size_m);
  if (s.empty()) return std::nullopt;
  const auto [p_in, p_out] = passage_interval(o, d, arch.half_span_m, arch.spring_z_m);
  const bool has_passage = p_in < p_out;
  // The solid is the box minus the passage; its entry points along the ray are the box entry (unless
  // that lies in the passage) and the passage exit (if it lies inside the box).
  if ((!has_passage || p_in > s.t_in || p_out < s.t_in) && s.t_in >= t_min && s.t_in <= t_max)
    return box_face_hit(box, o, d, s.t_in, s.axis_in);
  if (has_passage && p_out > s.t_in && p_out < s.t_out && p_out >= t_min && p_out <= t_max) {
    const Eigen::Vector3d p = o + p_out * d;
    const double r = arch.half_span_m, zs = arch.spring_z_m, h = box.half_size_m.z();
    Eigen::Vector3d n_local;
    double v;  // arc length along the passage profile, from the left foot over the crown to the right foot
    if (p.z() > zs) {
      n_local = -Eigen::Vector3d(p.x(), 0.0, p.z() - zs) / r;
      v = (zs + h) + r * std::atan2(p.z() - zs, -p.x());
    } else {
      n_local = Eigen::Vector3d(p.x() > 0.0 ? -1.0 : 1.0, 0.0, 0.0);
      v = p.x() < 0.0 ? p.z() + h : (zs + h) + r * std::numbers::pi + (zs - p.z());
    }
    return ShapeHit{p_out, facing(box.axes * n_local, ray.direction), {p.y() + box.half_size_m.y(), v}};
  }
  return std::nullopt;
}

std::optional<ShapeHit> intersect_height_field(const HeightField& f, const Ray& ray, double t_min, double t_max) {
  double amplitude = 0.0, slope = 0.0;  // bounds on |h - base| and |grad h|
  for (const auto& w : f.waves) {
    amplitude += std::abs(w.amplitude_m);
    slope += std::abs(w.amplitude_m) * std::hypot(w.kx, w.ky);
  }
  const Eigen::Vector3d lo(f.min_xy_m.x(), f.min_xy_m.y(), f.base_z_m - amplitude);
  const Eigen::Vector3d hi(f.max_xy_m.x(), f.max_xy_m.y(), f.base_z_m + amplitude);
  const Eigen::Vector3d& o = ray.origin;
  const Eigen::Vector3d& d = ray.direction;
  const SlabInterval s = slab_interval(o - 0.5 * (lo + hi), d, 0.5 * (hi - lo));
  double t = std::max(s.t_in, t_min);
  const double t_end = std::min(s.t_out, t_max);
  if (s.empty() || t > t_end) return std::nullopt;

  // Height of the ray above the terrain; it changes by at most `rate` per metre along the ray, so a
  // step of gap / rate cannot cross the surface (sphere tracing with a Lipschitz bound).
  auto gap = [&](double tt) { return o.z() + tt * d.z() - f.height(o.x() + tt * d.x(), o.y() + tt * d.y()); };
  const double rate = std::abs(d.z()) + slope * std::hypot(d.x(), d.y());
  constexpr double kMinStep = 0.05;  // m; terrain waves are tens of metres long, so nothing hides in a step
  double g = gap(t);
  if (g <= 0.0) return std::nullopt;  // starts below the terrain
  while (t < t_end) {
    const double t_next = std::min(t_end, t + std::max(g / rate, kMinStep));
    const double g_next = gap(t_next);
    if (g_next <= 0.0) {
      // Illinois regula falsi on [t, t_next], where the gap changes sign.
      double a = t, ga = g, b = t_next, gb = g_next;
      int side = 0;
      for (int it = 0; it < 60 && b - a > 1e-7; ++it) {
        const double m = (a * gb - b * ga) / (gb - ga);
        const double gm = gap(m);
        if (gm > 0.0) {
          a = m, ga = gm;
          if (side == -1) gb *= 0.5;
          side = -1;
        } else {
          b = m, gb = gm;
          if (side == 1) ga *= 0.5;
          side = 1;
        }
      }
      const Eigen::Vector3d p = o + b * d;
      return ShapeHit{b, facing(f.normal(p.x(), p.y()), d), {p.x(), p.y()}};
    }
    t = t_next, g = g_next;
  }
  return std::nullopt;
}

}  // namespace

double HeightField::height(double x, double y) const {
  double z = base_z_m;
  for (const auto& w : waves) z += w.amplitude_m * std::sin(w.kx * x + w.ky * y + w.phase);
  return z;
}

Eigen::Vector3d HeightField::normal(double x, double y) const {
  double gx = 0.0, gy = 0.0;
  for (const auto& w : waves) {
    const double c = w.amplitude_m * std::cos(w.kx * x + w.ky * y + w.phase);
    gx += c * w.kx;
    gy += c * w.ky;
  }
  return Eigen::Vector3d(-gx, -gy, 1.0).normalized();
}

std::optional<ShapeHit> intersect(const Shape& shape, const Ray& ray, double t_min, double t_max) {
  return std::visit(
      [&](const auto& s) -> std::optional<ShapeHit> {
        using T = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<T, Rect>) return intersect_rect(s, ray, t_min, t_max);
        if constexpr (std::is_same_v<T, Box>) return intersect_box(s, ray, t_min, t_max);
        if constexpr (std::is_same_v<T, Cylinder>) return intersect_cylinder(s, ray, t_min, t_max);
        if constexpr (std::is_same_v<T, Ellipsoid>) return intersect_ellipsoid(s, ray, t_min, t_max);
        if constexpr (std::is_same_v<T, ArchBlock>) return intersect_arch(s, ray, t_min, t_max);
        if constexpr (std::is_same_v<T, HeightField>) return intersect_height_field(s, ray, t_min, t_max);
      },
      shape);
}

Eigen::AlignedBox3d bounds(const Shape& shape) {
  return std::visit(
      [](const auto& s) -> Eigen::AlignedBox3d {
        using T = std::decay_t<decltype(s)>;
        Eigen::AlignedBox3d b;
        if constexpr (std::is_same_v<T, Rect>) {
          const Eigen::Vector3d u = s.u_size_m * s.u_axis, v = s.v_size_m * s.v_axis;
          b.extend(s.corner_m).extend(s.corner_m + u).extend(s.corner_m + v).extend(s.corner_m + u + v);
        } else if constexpr (std::is_same_v<T, Box> || std::is_same_v<T, ArchBlock>) {
          const Box& box = block_of(s);
          const Eigen::Vector3d extent = box.axes.cwiseAbs() * box.half_size_m;
          b.extend(box.center_m - extent).extend(box.center_m + extent);
        } else if constexpr (std::is_same_v<T, Cylinder>) {
          b.extend(Eigen::Vector3d(s.center_xy_m.x() - s.radius_m, s.center_xy_m.y() - s.radius_m, s.z_min_m));
          b.extend(Eigen::Vector3d(s.center_xy_m.x() + s.radius_m, s.center_xy_m.y() + s.radius_m, s.z_max_m));
        } else if constexpr (std::is_same_v<T, Ellipsoid>) {
          b.extend(s.center_m - s.radii_m).extend(s.center_m + s.radii_m);
        } else {
          double amplitude = 0.0;
          for (const auto& w : s.waves) amplitude += std::abs(w.amplitude_m);
          b.extend(Eigen::Vector3d(s.min_xy_m.x(), s.min_xy_m.y(), s.base_z_m - amplitude));
          b.extend(Eigen::Vector3d(s.max_xy_m.x(), s.max_xy_m.y(), s.base_z_m + amplitude));
        }
        return b;
      },
      shape);
}

}  // namespace k4reg::sim
