#include "sim/scanner.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "k4reg/util/error.h"
#include "sim/bvh.h"
#include "sim/random.h"

namespace k4reg::sim {
namespace {

using Eigen::Vector3d;

constexpr double kDegree = std::numbers::pi / 180.0;
constexpr double kMinElevation_rad = -60.0 * kDegree;  // below: the tripod's blind cone
constexpr double kMaxElevation_rad = 90.0 * kDegree;
constexpr double kMinRange_m = 0.4;                     // real scanners see nothing closer
constexpr std::size_t kPilotRays = 50000;               // estimates the hit fraction to within ~1 %
constexpr double kMinHitFraction = 0.05;                // caps the rays at 20 x points for empty views
constexpr std::size_t kMaxPoints = 50'000'000;
constexpr double kCutoffCos = 0.05;                     // no return at more grazing incidence
constexpr double kFadeCos = 0.25;                       // below this, returns thin out towards the cutoff
constexpr double kAttenuationRange_m = 150.0;           // intensity falls to 1/2 at this range
constexpr double kMinSignal = 0.004;                    // weaker echoes are lost
constexpr double kIntensityNoise = 0.01;
constexpr double kGlassReturn = 0.15;                   // share of beams a pane reflects
constexpr double kGlassNoiseFactor = 5.0;               // pane returns are mixed echoes: noisier
constexpr double kFoliageReturn = 0.5;                  // share of beams leaves stop
constexpr int kMaxPassThrough = 8;
constexpr double kPassThroughGap_m = 1e-4;              // restart just behind a transmitting surface
constexpr double kUpExclusion_rad = 10.0 * kDegree;

// Constant angular sampling: `columns` vertical profiles over 360 deg, `rows` elevations each, from
// the bottom of the field of view up. Rows sit at half steps, so no row collapses onto the zenith.
struct AngularGrid {
  double step_rad = 0.0;
  double azimuth0_rad = 0.0;
  std::size_t columns = 0, rows = 0;

  std::size_t rays() const { return columns * rows; }
  Vector3d direction(std::size_t column, std::size_t row) const {
    const double az = azimuth0_rad + 2.0 * std::numbers::pi * static_cast<double>(column) / static_cast<double>(columns);
    const double el = kMinElevation_rad + step_rad * (static_cast<double>(row) + 0.5);
    return Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
  }
};

// The step for which columns x rows ~ rays: (2 pi / step) x (span / step) = rays.
AngularGrid grid_for(double rays, double azimuth0_rad) {
  const double span = kMaxElevation_rad - kMinElevation_rad;
  AngularGrid g;
  g.step_rad = std::sqrt(2.0 * std::numbers::pi * span / rays);
  g.azimuth0_rad = azimuth0_rad;
  g.columns = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(2.0 * std::numbers::pi / g.step_rad)));
  g.rows = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(span / g.step_rad)));
  return g;
}

// The object range scanner's rays: through the centres of a columns x rows grid of pixels of equal
// pitch on the image plane, over a square field of view around `forward` (a camera's sampling).
struct FrustumGrid {
  Vector3d forward, right, up;  // unit, orthogonal; right and up span the image plane
  double tan_half = 0.0;        // tangent of half the field of view
  double step_rad = 0.0;        // angular pitch at the centre of the view
  std::size_t columns = 0, rows = 0;

  std::size_t rays() const { return columns * rows; }
  Vector3d direction(std::size_t column, std::size_t row) const {
    const double a = tan_half * (2.0 * (static_cast<double>(column) + 0.5) / static_cast<double>(columns) - 1.0);
    const double b = tan_half * (2.0 * (static_cast<double>(row) + 0.5) / static_cast<double>(rows) - 1.0);
    return (forward + a * right + b * up).normalized();
  }
};

FrustumGrid frustum_for(double rays, const Vector3d& forward, double field_of_view_rad) {
  FrustumGrid g;
  g.forward = forward;
  // Image rows stay horizontal unless the scanner looks (nearly) straight up or down.
  const Vector3d level = std::abs(forward.z()) < 0.999 ? Vector3d::UnitZ() : Vector3d::UnitX();
  g.right = forward.cross(level).normalized();
  g.up = g.right.cross(forward);
  g.tan_half = std::tan(0.5 * field_of_view_rad);
  g.columns = g.rows = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(std::sqrt(rays))));
  g.step_rad = field_of_view_rad / static_cast<double>(g.columns);
  return g;
}

struct Return {
  Vector3d point_m;
  float intensity;
};

// One laser measurement from `origin` along `direction`, or nothing if no echo comes back.
std::optional<Return> measure(const SceneIndex& index, const Vector3d& origin, const Vector3d& direction,
                              double max_range_m, double noise_m, RandomStream& rng) {
  double t_min = kMinRange_m;
  for (int pass = 0; pass <= kMaxPassThrough; ++pass) {
    const auto hit = index.closest_hit(Ray{origin, direction}, t_min, max_range_m);
    if (!hit) return std::nullopt;
    double noise = noise_m;
    if (hit->material == Material::kGlass) {
      if (rng.uniform() >= kGlassReturn) {
        t_min = hit->distance_m + kPassThroughGap_m;
        continue;
      }
      noise *= kGlassNoiseFactor;
    } else if (hit->material == Material::kFoliage && rng.uniform() >= kFoliageReturn) {
      t_min = hit->distance_m + kPassThroughGap_m;
      continue;
    }
    const double cos_incidence = std::abs(hit->normal.dot(direction));
    if (cos_incidence < kCutoffCos) return std::nullopt;
    if (cos_incidence < kFadeCos) {
      const double grazing = (kFadeCos - cos_incidence) / (kFadeCos - kCutoffCos);
      if (rng.uniform() < grazing * grazing) return std::nullopt;
    }
    const double signal = hit->reflectivity * cos_incidence / (1.0 + hit->distance_m / kAttenuationRange_m);
    if (signal < kMinSignal) return std::nullopt;
    const double range = hit->distance_m + noise * rng.normal();
    const double intensity = std::clamp(signal + kIntensityNoise * rng.normal(), 0.0, 1.0);
    return Return{origin + range * direction, static_cast<float>(intensity)};
  }
  return std::nullopt;
}

// Shoemake's uniform random unit quaternion, redrawn while the scene's up axis would stay within
// kUpExclusion_rad of the scan's z axis.
Eigen::Matrix3d random_rotation(RandomStream& rng) {
  for (;;) {
    const double u = rng.uniform(), a = 2.0 * std::numbers::pi * rng.uniform(), b = 2.0 * std::numbers::pi * rng.uniform();
    const Eigen::Quaterniond q(std::sqrt(u) * std::cos(b), std::sqrt(1.0 - u) * std::sin(a),
                               std::sqrt(1.0 - u) * std::cos(a), std::sqrt(u) * std::sin(b));
    const Eigen::Matrix3d r = q.normalized().toRotationMatrix();
    if (r(2, 2) < std::cos(kUpExclusion_rad)) return r;
  }
}

void validate(std::size_t points, double noise_m, const ScanParams& params, const Station& station) {
  if (points < 1000 || points > kMaxPoints)
    fail(ErrorCode::kInvalidArgument, "points must be between 1000 and " + std::to_string(kMaxPoints) + ", not " +
                                          std::to_string(points));
  if (!(noise_m >= 0.0 && noise_m <= 1.0))
    fail(ErrorCode::kInvalidArgument, "range noise must be between 0 and 1 m, not " + std::to_string(noise_m));
  if (!(params.max_range_m >= 0.0 && std::isfinite(params.max_range_m)))
    fail(ErrorCode::kInvalidArgument, "maximum range must be >= 0 m (0 = scene default), not " +
                                          std::to_string(params.max_range_m));
  if (station.look_at_m && !((*station.look_at_m - station.position_m).norm() > 0.0 &&
                             station.field_of_view_deg > 0.0 && station.field_of_view_deg < 170.0))
    fail(ErrorCode::kInvalidArgument, "an aimed station needs a target away from it and a field of view in (0, 170) deg");
}

}  // namespace

SimulatedScan simulate_scan(const Scene& scene, int station, const ScanParams& params) {
  std::vector<Primitive> primitives = scene.primitives_seen_from(station);  // checks the station
  const Station& where = scene.stations[station];
  const std::size_t points_wanted = params.points > 0 ? params.points : scene.default_points;
  const double noise_m = params.noise_m.value_or(scene.default_noise_m);
  validate(points_wanted, noise_m, params, where);
  const double max_range_m = params.max_range_m > 0.0 ? params.max_range_m : scene.default_max_range_m;
  const SceneIndex index(std::move(primitives));
  const Vector3d origin = where.position_m;

  std::uint64_t scene_key = 0xcbf29ce484222325ULL;  // FNV-1a of the name: each scene has its own rotations
  for (const char c : scene.name) scene_key = (scene_key ^ static_cast<unsigned char>(c)) * 0x100000001b3ULL;
  if (scene.layout > 0) scene_key = derive_key(scene_key, static_cast<std::uint64_t>(scene.layout));  // its own rotations too
  const std::uint64_t scan_key = derive_key(derive_key(params.seed, scene_key), static_cast<std::uint64_t>(station));
  RandomStream scan_rng(scan_key);
  const double azimuth0_rad = 2.0 * std::numbers::pi * scan_rng.uniform();  // scanners start anywhere
  const Eigen::Matrix3d scan_to_scene_rotation = random_rotation(scan_rng);
  const Eigen::Matrix3d scene_to_scan_rotation = scan_to_scene_rotation.transpose();

  // Each column is traced by one task into its own buffers, which are concatenated in column order;
  // every ray's random stream depends only on its index, so the result is independent of threading.
  auto trace = [&](const auto& grid, std::uint64_t rays_key, std::vector<std::vector<Eigen::Vector3f>>& points,
                   std::vector<std::vector<float>>& intensity) {
    points.assign(grid.columns, {});
    intensity.assign(grid.columns, {});
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, grid.columns), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t c = r.begin(); c != r.end(); ++c) {
        for (std::size_t row = 0; row < grid.rows; ++row) {
          RandomStream rng(derive_key(rays_key, c * grid.rows + row));
          const Vector3d direction = grid.direction(c, row);
          const auto ret = measure(index, origin, direction, max_range_m, noise_m, rng);
          if (!ret) continue;
          points[c].push_back((scene_to_scan_rotation * (ret->point_m - origin)).cast<float>());
          if (scene.intensity) intensity[c].push_back(ret->intensity);
        }
      }
    });
  };
  std::vector<std::vector<Eigen::Vector3f>> points;
  std::vector<std::vector<float>> intensity;

  // A coarse pilot scan measures the hit fraction (sky, windows and range limit return nothing), so the
  // real scan can cast just enough rays for the requested number of points. grid_of(rays) lays the rays.
  SimulatedScan scan;
  auto pilot_then_scan = [&](const auto& grid_of) {
    const auto pilot = grid_of(static_cast<double>(kPilotRays));
    trace(pilot, derive_key(scan_key, 1), points, intensity);
    std::size_t pilot_hits = 0;
    for (const auto& column : points) pilot_hits += column.size();
    const double hit_fraction =
        std::max(kMinHitFraction, static_cast<double>(pilot_hits) / static_cast<double>(pilot.rays()));
    const auto grid = grid_of(static_cast<double>(points_wanted) / hit_fraction);
    trace(grid, derive_key(scan_key, 2), points, intensity);
    scan.step_rad = grid.step_rad;
    scan.rays = grid.rays();
  };
  if (where.look_at_m) {
    const Vector3d forward = (*where.look_at_m - origin).normalized();
    const double field_of_view_rad = where.field_of_view_deg * kDegree;
    pilot_then_scan([&](double rays) { return frustum_for(rays, forward, field_of_view_rad); });
  } else {
    pilot_then_scan([&](double rays) { return grid_for(rays, azimuth0_rad); });
  }

  std::size_t total = 0;
  for (const auto& column : points) total += column.size();
  scan.cloud.points.reserve(total);
  if (scene.intensity) scan.cloud.intensity.reserve(total);
  for (std::size_t c = 0; c < points.size(); ++c) {
    scan.cloud.points.insert(scan.cloud.points.end(), points[c].begin(), points[c].end());
    scan.cloud.intensity.insert(scan.cloud.intensity.end(), intensity[c].begin(), intensity[c].end());
    std::vector<Eigen::Vector3f>().swap(points[c]);  // keeps the peak memory near one copy of the scan
    std::vector<float>().swap(intensity[c]);
  }
  // An arbitrary frame moves the scanner off the origin: p_file = p_scan + shift (kept exact in origin_m).
  Vector3d shift = Vector3d::Zero();
  if (params.frame == ScanFrame::kArbitrary) {
    RandomStream frame_rng(derive_key(scan_key, 3));
    for (int axis = 0; axis < 3; ++axis) shift(axis) = kArbitraryShiftM * (2.0 * frame_rng.uniform() - 1.0);
  }
  scan.cloud.origin_m = shift;
  scan.scan_to_scene.setIdentity();
  scan.scan_to_scene.topLeftCorner<3, 3>() = scan_to_scene_rotation;
  scan.scan_to_scene.topRightCorner<3, 1>() = origin - scan_to_scene_rotation * shift;
  scan.station_m = origin;
  return scan;
}

}  // namespace k4reg::sim
