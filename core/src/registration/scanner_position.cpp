#include "k4reg/registration/scanner_position.h"

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <utility>

#include "k4reg/geometry/hash_map.h"
#include "k4reg/geometry/voxel_grid.h"
#include "k4reg/registration/scanner_sampling.h"
#include "k4reg/util/held_bytes.h"
#include "k4reg/util/median.h"

namespace k4reg {

const char* to_string(ScannerSource source) {
  switch (source) {
    case ScannerSource::kOrigin: return "origin";
    case ScannerSource::kFile: return "file";
    case ScannerSource::kEstimated: return "estimated";
    case ScannerSource::kNone: break;
  }
  return "none";
}

ScannerSource scanner_source_named(const std::string& name) {
  for (const ScannerSource source : {ScannerSource::kOrigin, ScannerSource::kFile, ScannerSource::kEstimated})
    if (name == to_string(source)) return source;
  return ScannerSource::kNone;
}

namespace {

// Search cells grow by this factor per level, from kLevelFactor spacings up (256 at the last): far points of a scan
// are tens of times sparser than its median, and a grid of cells much finer than a query's neighbour distance costs a
// look-up per cell. Cells of one spacing would settle only a third of the queries (six neighbours seldom lie within
// one spacing) for a pass over the whole cloud; those they settle find the same six in cells four times as large.
constexpr double kLevelFactor = 4.0;
constexpr int kLevels = 4;
constexpr double kAcrossCosine = 0.7071;  // 45 degrees
constexpr double kMinAngleRatio = 0.25;   // the cosine of 75 degrees

// The share of neighbour pairs one step apart (within kStepTolerance) that a scanner's position gives: 0.72-0.84 on
// simulated stations and 0.67-0.68 on real ones (Kurt3D's swept profiler), against 0.22-0.49 where a search ended
// away from the scanner and 0.05-0.12 for merged, resampled or fused clouds (a Velodyne's beams, 1-2 degrees
// apart, give 0.02: too far apart to be one step).
constexpr double kMinScannerShare = 0.5;

}  // namespace

NeighbourAngles::NeighbourAngles(const std::vector<Eigen::Vector3f>& points, double spacing_m, std::size_t pairs,
                                 const CancellationToken* cancel) {
  if (points.size() < 2 || !(spacing_m > 0)) return;
  const std::size_t stride = std::max<std::size_t>(1, points.size() / pairs);
  std::vector<std::size_t> queries;
  for (std::size_t i = stride / 2; i < points.size(); i += stride) queries.push_back(i);
  // Per query, its nearest neighbours once found (empty until then).
  std::vector<std::vector<std::pair<float, std::uint32_t>>> found(queries.size());
  // Duplicates (a point returned twice) are no neighbours: their angle is 0 from anywhere.
  const float tiny2 = static_cast<float>(1e-6 * spacing_m * spacing_m);
  double cell = kLevelFactor * spacing_m;
  for (int level = 0; level < kLevels; ++level, cell *= kLevelFactor) {
    // The cells around the queries still open, and one pass over the cloud for the points in them: far cheaper than
    // a grid over the whole cloud, as the queries are a few thousand.
    const float inverse = static_cast<float>(1.0 / cell);
    VoxelKeyMap around(queries.size() * 27);
    KeyBits near_queries(queries.size() * 27);  // most points lie near none of the queries
    std::uint32_t buckets = 0;
    for (std::size_t q = 0; q < queries.size(); ++q) {
      if (!found[q].empty()) continue;
      const Eigen::Vector3i home = voxel_index(points[queries[q]], inverse);
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            bool inserted = false;
            const std::uint64_t key = pack_voxel_key(home + Eigen::Vector3i(dx, dy, dz));
            around.find_or_insert(key, buckets, inserted);
            near_queries.add(key);
            buckets += inserted;
          }
    }
    if (buckets == 0) break;
    check(cancel);
    // The look-ups (most of the time) in parallel, the cells filled in point order: the same lists on any thread count.
    std::vector<std::uint32_t> bucket_of(points.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 16384), [&](const auto& range) {
      for (std::size_t i = range.begin(); i != range.end(); ++i) {
        const std::uint64_t key = pack_voxel_key(voxel_index(points[i], inverse));
        bucket_of[i] = near_queries.may_hold(key) ? around.find(key) : VoxelKeyMap::kAbsent;
      }
    });
    std::vector<std::vector<std::uint32_t>> in_cell(buckets);
    for (std::size_t i = 0; i < points.size(); ++i)
      if (bucket_of[i] != VoxelKeyMap::kAbsent) in_cell[bucket_of[i]].push_back(static_cast<std::uint32_t>(i));
    const float radius2 = static_cast<float>(cell * cell);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, queries.size(), 256), [&](const auto& range) {
      std::vector<std::pair<float, std::uint32_t>> near;
      for (std::size_t q = range.begin(); q != range.end(); ++q) {
        if (!found[q].empty()) continue;
        const Eigen::Vector3f& p = points[queries[q]];
        const Eigen::Vector3i home = voxel_index(p, inverse);
        near.clear();
        for (int dz = -1; dz <= 1; ++dz)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx)
              for (const std::uint32_t k : in_cell[around.find(pack_voxel_key(home + Eigen::Vector3i(dx, dy, dz)))]) {
                const float d2 = (points[k] - p).squaredNorm();
                if (d2 > tiny2 && d2 <= radius2) near.emplace_back(d2, k);
              }
        // Enough neighbours within this level's radius, or the last level's best.
        if (near.size() < kNeighbours && level + 1 < kLevels) continue;
        if (near.size() < 2) continue;
        const std::size_t kept = std::min(near.size(), kNeighbours);
        std::partial_sort(near.begin(), near.begin() + static_cast<std::ptrdiff_t>(kept), near.end());
        found[q].assign(near.begin(), near.begin() + static_cast<std::ptrdiff_t>(kept));
      }
    });
  }
  for (std::size_t q = 0; q < queries.size(); ++q) {
    if (found[q].empty()) continue;
    points_.push_back(points[queries[q]]);
    for (std::size_t k = 0; k < kNeighbours; ++k)
      neighbours_.push_back(points[found[q][std::min(k, found[q].size() - 1)].second]);
  }
}

NeighbourAngles NeighbourAngles::thinned(std::size_t pairs) const {
  NeighbourAngles out;
  const std::size_t stride = std::max<std::size_t>(1, points_.size() / std::max<std::size_t>(pairs, 1));
  for (std::size_t i = 0; i < points_.size(); i += stride) {
    out.points_.push_back(points_[i]);
    out.neighbours_.insert(out.neighbours_.end(), neighbours_.begin() + static_cast<std::ptrdiff_t>(i * kNeighbours),
                           neighbours_.begin() + static_cast<std::ptrdiff_t>((i + 1) * kNeighbours));
  }
  return out;
}

std::size_t NeighbourAngles::bytes() const { return held_bytes(points_) + held_bytes(neighbours_); }

std::vector<Eigen::Vector3f> NeighbourAngles::near_scanner_candidates() const {
  std::vector<std::pair<float, std::size_t>> by_distance;
  for (std::size_t i = 0; i < points_.size(); ++i) by_distance.emplace_back((points_[i] - neighbours_[i * kNeighbours]).norm(), i);
  std::sort(by_distance.begin(), by_distance.end());
  std::vector<Eigen::Vector3f> candidates;
  for (const double share : {0.02, 0.1}) {
    const std::size_t count = static_cast<std::size_t>(share * by_distance.size());
    if (count < 3) continue;
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < count; ++k) centroid += points_[by_distance[k].second].cast<double>();
    centroid /= static_cast<double>(count);
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (std::size_t k = 0; k < count; ++k) {
      const Eigen::Vector3d d = points_[by_distance[k].second].cast<double>() - centroid;
      scatter += d * d.transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter / static_cast<double>(count));
    const Eigen::Vector3d axis = solver.eigenvectors().col(0);  // the ring's normal
    const double radius = std::sqrt(std::max(0.0, solver.eigenvalues()(1) + solver.eigenvalues()(2)));
    candidates.push_back(centroid.cast<float>());
    for (const double heights : {0.5, 1.0, 1.5, 2.0, 3.0})
      for (const double side : {-1.0, 1.0}) candidates.push_back((centroid + side * heights * radius * axis).cast<float>());
  }
  return candidates;
}

std::vector<double> NeighbourAngles::log_steps(const Eigen::Vector3d& scanner_m) const {
  std::vector<double> logs(points_.size(), std::numeric_limits<double>::quiet_NaN());
  std::array<Eigen::Vector3d, kNeighbours> turns;  // direction changes to the neighbours, across the ray
  std::array<double, kNeighbours> angles;
  for (std::size_t i = 0; i < points_.size(); ++i) {
    const Eigen::Vector3d u = points_[i].cast<double>() - scanner_m;
    const double ru = u.norm();
    const Eigen::Vector3f* near = &neighbours_[i * kNeighbours];
    // Within a few neighbour distances of the candidate the angles say nothing about a scanner's step.
    if (ru < 4.0 * (points_[i] - near[kNeighbours - 1]).norm()) continue;
    const Eigen::Vector3d ray = u / ru;
    std::size_t nearest = 0;
    for (std::size_t k = 0; k < kNeighbours; ++k) {
      turns[k] = (near[k].cast<double>() - scanner_m).normalized() - ray;
      angles[k] = turns[k].norm();
      if (angles[k] < angles[nearest]) nearest = k;
    }
    // Seen from a scanner, the neighbours in the image lie one step apart across its profiles and the step times the
    // cosine of the elevation along them (range noise moves points along the ray and changes neither): the larger
    // of the nearest and the nearest in another direction (more than 45 degrees from it) is the step.
    std::size_t across = kNeighbours;
    for (std::size_t k = 0; k < kNeighbours; ++k)
      if (angles[k] > 0 && std::abs(turns[k].dot(turns[nearest])) < kAcrossCosine * angles[k] * angles[nearest] &&
          (across == kNeighbours || angles[k] < angles[across]))
        across = k;
    if (across == kNeighbours || !(angles[nearest] > 0)) continue;
    // A neighbour nearly in line with the candidate says nothing: seen from a scanner's foot, the ground's
    // neighbours along the profiles subtend one step and those across them next to nothing (the zenith's few, whose
    // cosine is that small, are left out with them).
    const double step = std::max(angles[nearest], angles[across]);
    if (std::min(angles[nearest], angles[across]) >= kMinAngleRatio * step) logs[i] = std::log(step);
  }
  return logs;
}

SamplingFit NeighbourAngles::fit_at(const Eigen::Vector3f& scanner_m, double tolerance) const {
  std::vector<double> logs = log_steps(scanner_m.cast<double>());
  logs.erase(std::remove_if(logs.begin(), logs.end(), [](double l) { return std::isnan(l); }), logs.end());
  // The densest window of log angles, 2 log(1 + tolerance) wide: the step, and the share of neighbours one step
  // apart.
  SamplingFit fit;
  if (logs.empty()) return fit;
  const double width = 2.0 * std::log1p(tolerance);
  std::sort(logs.begin(), logs.end());
  std::size_t most = 0, low = 0;
  for (std::size_t high = 0; high < logs.size(); ++high) {
    while (logs[high] - logs[low] > width) ++low;
    if (high - low + 1 > most) most = high - low + 1, fit.step_rad = std::exp(0.5 * (logs[high] + logs[low]));
  }
  fit.share = static_cast<double>(most) / static_cast<double>(points_.size());
  return fit;
}

bool fits_a_scanner(const SamplingFit& fit) { return fit.share >= kMinScannerShare; }

namespace {

// The position and log step that make the log neighbour angles most alike under a Cauchy loss of the given scale,
// by Levenberg-Marquardt from `at` (derivatives by differences of `h_m`). The loss is smooth where the share of a
// window is not, so a wide scale's optimum can be followed as the scale narrows.
struct Refined {
  Eigen::Vector3d at;
  double log_step;
};
Refined refine(const NeighbourAngles& angles, Refined x, double scale, double h_m, const CancellationToken* cancel) {
  auto cost_of = [&](const std::vector<double>& logs, double log_step) {
    double cost = 0.0;
    for (const double l : logs) {
      const double e = std::isnan(l) ? 1.0 : (l - log_step) / scale;
      cost += std::log1p(e * e);
    }
    return cost;
  };
  std::vector<double> logs = angles.log_steps(x.at);
  double cost = cost_of(logs, x.log_step), lambda = 1e-3;
  for (int iteration = 0; iteration < 30; ++iteration) {
    check(cancel);
    std::array<std::vector<double>, 3> moved;
    for (int axis = 0; axis < 3; ++axis) {
      Eigen::Vector3d at = x.at;
      at(axis) += h_m;
      moved[axis] = angles.log_steps(at);
    }
    Eigen::Matrix4d normal = Eigen::Matrix4d::Zero();
    Eigen::Vector4d gradient = Eigen::Vector4d::Zero();
    for (std::size_t i = 0; i < logs.size(); ++i) {
      if (std::isnan(logs[i]) || std::isnan(moved[0][i]) || std::isnan(moved[1][i]) || std::isnan(moved[2][i])) continue;
      const double e = logs[i] - x.log_step, w = 1.0 / (1.0 + (e / scale) * (e / scale));
      const Eigen::Vector4d j((moved[0][i] - logs[i]) / h_m, (moved[1][i] - logs[i]) / h_m, (moved[2][i] - logs[i]) / h_m,
                              -1.0);
      normal += w * j * j.transpose();
      gradient += w * j * e;
    }
    bool improved = false;
    while (!improved && lambda < 1e6) {
      Eigen::Matrix4d damped = normal;
      damped.diagonal() *= 1.0 + lambda;
      const Eigen::Vector4d delta = -damped.ldlt().solve(gradient);
      const Refined trial{x.at + delta.head<3>(), x.log_step + delta(3)};
      std::vector<double> trial_logs = angles.log_steps(trial.at);
      const double trial_cost = cost_of(trial_logs, trial.log_step);
      if (trial_cost < cost) {
        const bool converged = delta.head<3>().norm() < 0.1 * h_m;
        x = trial, logs = std::move(trial_logs), cost = trial_cost, lambda *= 0.3, improved = true;
        if (converged) return x;
      } else {
        lambda *= 4.0;
      }
    }
    if (!improved) break;
  }
  return x;
}

}  // namespace

ScannerEstimate estimate_scanner_position(const NeighbourAngles& angles, const CancellationToken* cancel) {
  ScannerEstimate out;
  const std::vector<Eigen::Vector3f>& points = angles.points();
  if (points.size() < 64) {
    out.reason = "too few points to judge the sampling";
    return out;
  }
  // The robust box of the sampled points (2nd to 98th percentile): a terrestrial scanner stands inside what it
  // scanned.
  Eigen::Vector3f low, high;
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<float> values;
    values.reserve(points.size());
    for (const Eigen::Vector3f& p : points) values.push_back(p(axis));
    std::sort(values.begin(), values.end());
    low(axis) = values[values.size() * 2 / 100];
    high(axis) = values[values.size() * 98 / 100];
  }
  const Eigen::Vector3f extent = (high - low).cwiseMax(1e-3f);

  // Candidates: the centres of a grid over the box and the points up the axis of the densest points' ring
  // (near_scanner_candidates), the best few of each by the share of a wide window. Each is refined under a loss
  // whose scale narrows from a wide basin to the step's precision; the one with the largest share of neighbours one
  // step apart wins.
  struct Candidate {
    Eigen::Vector3f at;
    SamplingFit fit;
  };
  std::vector<Candidate> candidates;
  // The wide stages judge a quarter of the pairs: their basin is metres wide, and a thousand pairs show it.
  const NeighbourAngles coarse = angles.thinned(angles.points().size() / 4);
  constexpr int kCells = 8;
  constexpr double kCoarseTolerance = 0.3;
  for (int x = 0; x < kCells; ++x)
    for (int y = 0; y < kCells; ++y) {
      check(cancel);
      for (int z = 0; z < kCells; ++z) {
        const Eigen::Vector3f at = low + extent.cwiseProduct(Eigen::Vector3f(x + 0.5f, y + 0.5f, z + 0.5f) / kCells);
        candidates.push_back({at, coarse.fit_at(at, kCoarseTolerance)});
      }
    }
  constexpr std::size_t kRefined = 3;
  auto better = [](const Candidate& a, const Candidate& b) { return a.fit.share > b.fit.share; };
  std::partial_sort(candidates.begin(), candidates.begin() + kRefined, candidates.end(), better);
  candidates.resize(kRefined);
  std::vector<Candidate> near;
  for (const Eigen::Vector3f& at : angles.near_scanner_candidates()) near.push_back({at, coarse.fit_at(at, kCoarseTolerance)});
  constexpr std::size_t kNearRefined = 2;
  std::partial_sort(near.begin(), near.begin() + std::min(kNearRefined, near.size()), near.end(), better);
  candidates.insert(candidates.end(), near.begin(), near.begin() + std::min(kNearRefined, near.size()));
  // Candidates that meet on the way are refined once.
  const double h_m = 2e-4 * extent.maxCoeff();
  std::vector<Candidate> found;
  for (const Candidate& c : candidates) {
    Refined x{c.at.cast<double>(), std::log(std::max(c.fit.step_rad, 1e-9))};
    for (const double scale : {0.3, 0.1}) x = refine(coarse, x, scale, h_m, cancel);
    const Eigen::Vector3f wide = x.at.cast<float>();
    if (std::any_of(found.begin(), found.end(), [&](const Candidate& f) { return (f.at - wide).norm() < 0.01f * extent.maxCoeff(); }))
      continue;
    for (const double scale : {0.03, 0.01}) x = refine(angles, x, scale, h_m, cancel);
    const Eigen::Vector3f at = x.at.cast<float>();
    found.push_back({at, angles.fit_at(at)});
  }
  const Candidate& best = *std::min_element(found.begin(), found.end(), better);
  out.position_m = best.at;
  out.fit = best.fit;
  out.found = fits_a_scanner(best.fit);
  if (!out.found)
    out.reason = fmt::format(
        "no single constant-angle scanner: from the best position only {:.0f} % of neighbouring points lie one angular "
        "step apart (a scanner's own sampling: {:.0f} % or more); merged scans, or a resampled cloud",
        100 * best.fit.share, 100 * kMinScannerShare);
  return out;
}

namespace {

constexpr double kMinScannerRange = 1.0;  // a terrestrial scanner's median range, at least

Eigen::AlignedBox3f bounds(const std::vector<Eigen::Vector3f>& points) {
  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f& p : points) box.extend(p);
  return box;
}

}  // namespace

bool surrounded_by(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& at) {
  if (points.empty() || !bounds(points).contains(at)) return false;
  std::vector<double> ranges;
  ranges.reserve(points.size());
  for (const Eigen::Vector3f& p : points) ranges.push_back((p - at).norm());
  return median(std::move(ranges)) >= kMinScannerRange;
}

bool could_surround_a_scanner(const std::vector<Eigen::Vector3f>& points) {
  return !points.empty() && bounds(points).diagonal().norm() >= kMinScannerRange;
}

namespace {

// What the file declares: its scan pose where it has one, else its frame's origin. Either can be wrong (a scan
// exported in project coordinates with an identity pose, shifted or merged by another tool), so the sampling
// judges it.
struct Declared {
  ScannerSource source;
  Eigen::Vector3d position_m;  // file frame
  bool possible;               // surrounded_by
  SamplingFit fit;
  const char* what() const { return source == ScannerSource::kFile ? "the file's scan pose" : "the frame's origin"; }
  ScannerPosition taken(const char* why) const { return {source, position_m, fit, std::string(what()) + why}; }
};

Declared declared_by(const PointCloud& cloud, const NeighbourAngles& angles) {
  Declared d{cloud.scanner_m ? ScannerSource::kFile : ScannerSource::kOrigin, cloud.scanner_m.value_or(Eigen::Vector3d::Zero()),
             false, {}};
  const Eigen::Vector3f local = (d.position_m - cloud.origin_m).cast<float>();
  d.possible = surrounded_by(cloud.points, local);
  d.fit = angles.fit_at(local);
  return d;
}

}  // namespace

ScannerPosition check_declared_scanner(const PointCloud& cloud, const NeighbourAngles& angles) {
  const Declared d = declared_by(cloud, angles);
  if (d.possible && fits_a_scanner(d.fit)) return d.taken(": the sampling confirms it");
  ScannerPosition none;
  none.fit = d.fit;
  none.reason = std::string(d.what()) + (d.possible ? " does not fit the sampling" : " cannot be a terrestrial scanner's") +
                ", and no other position was searched";
  return none;
}

ScannerPosition locate_scanner(const PointCloud& cloud, const NeighbourAngles& angles, const CancellationToken* cancel) {
  const Declared d = declared_by(cloud, angles);
  if (d.possible && fits_a_scanner(d.fit)) return d.taken(": the sampling confirms it");
  const ScannerEstimate estimate = estimate_scanner_position(angles, cancel);
  // A scan whose sampling fits no scanner well (a swept 2D profiler, a noisy cloud) keeps a declared position that
  // could be its scanner's, unless a position elsewhere fits clearly better.
  constexpr double kClearlyBetter = 1.5;
  if (d.possible && (!estimate.found || kClearlyBetter * d.fit.share >= estimate.fit.share))
    return d.taken(": it could be the scanner's, and no position fits the sampling clearly better");
  if (!estimate.found) return {ScannerSource::kNone, Eigen::Vector3d::Zero(), estimate.fit, estimate.reason};
  return {ScannerSource::kEstimated, cloud.origin_m + estimate.position_m.cast<double>(), estimate.fit,
          std::string("estimated from the scan's sampling (") + d.what() +
              (d.possible ? " fits it worse)" : " cannot be a scanner's)")};
}

ScannerPosition locate_scanner(const PointCloud& cloud, double spacing_m, const CancellationToken* cancel) {
  return locate_scanner(cloud, NeighbourAngles(cloud.points, spacing_m, 4096, cancel), cancel);
}

}  // namespace k4reg
