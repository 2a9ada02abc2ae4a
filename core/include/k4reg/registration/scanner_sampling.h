// The search behind scanner_position.h: pairs of neighbouring points sampled from a scan, and the position seen from
// which most of them lie one angular step apart.
// Cost: nearest neighbours of 4096 sampled points (a hashed grid over the cloud per spacing level it needs); each
// judged position costs one pass over the pairs (a sort for fit_at); the search judges about 1500.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "k4reg/registration/scanner_position.h"
#include "k4reg/util/cancellation.h"

namespace k4reg {

// A neighbour angle within this relative tolerance of the step counts as one step.
constexpr double kStepTolerance = 0.03;

struct ScannerEstimate {
  bool found = false;
  Eigen::Vector3f position_m = Eigen::Vector3f::Zero();  // in the points' frame
  SamplingFit fit;           // at position_m
  std::string reason;        // why none was found (empty when found)
};

// Pairs of neighbouring points sampled from a scan, on which candidate scanner positions are judged.
class NeighbourAngles {
 public:
  NeighbourAngles() = default;
  // Up to `pairs` points spread through the cloud (by index), each with its kNeighbours nearest other points (a
  // scanner's neighbours along and across its profiles are among them).
  // spacing_m: the cloud's typical point spacing (sampling.h), the finest search cell.
  NeighbourAngles(const std::vector<Eigen::Vector3f>& points, double spacing_m, std::size_t pairs = 4096,
                  const CancellationToken* cancel = nullptr);
  SamplingFit fit_at(const Eigen::Vector3f& scanner_m, double tolerance = kStepTolerance) const;
  // Per sampled point, the log of the larger of two neighbour angles seen from scanner_m, the nearest and the
  // nearest in another direction (the step, from a scanner); NaN where that cannot be told.
  std::vector<double> log_steps(const Eigen::Vector3d& scanner_m) const;
  // Where a scanner may stand, from the densest points (those closest to their nearest neighbour: 2 and 10 % of
  // them): a scanner's nearest returns are the ground around the foot of its tripod, a ring about its vertical,
  // so it stands on the ring's axis, its height a few times the ring's radius. The centroids and points up that
  // axis at 0.5-3 radii, both ways.
  std::vector<Eigen::Vector3f> near_scanner_candidates() const;
  const std::vector<Eigen::Vector3f>& points() const { return points_; }
  // Every k-th of the points with their neighbours, about `pairs` of them.
  NeighbourAngles thinned(std::size_t pairs) const;
  std::size_t bytes() const;  // heap bytes held

  static constexpr std::size_t kNeighbours = 6;

 private:
  std::vector<Eigen::Vector3f> points_;
  std::vector<Eigen::Vector3f> neighbours_;  // kNeighbours per point, nearest first
};

// The position seen from which most neighbour pairs lie one angular step apart, searched within the points' robust
// extent, or none (with the reason) where even the best position leaves too few so, as in a cloud without one
// scanner's sampling. Deterministic. Throws kCancelled / kDeadlineExceeded when `cancel` fires.
ScannerEstimate estimate_scanner_position(const NeighbourAngles& angles, const CancellationToken* cancel = nullptr);

// locate_scanner (scanner_position.h) on neighbour angles already sampled from the cloud.
ScannerPosition locate_scanner(const PointCloud& cloud, const NeighbourAngles& angles,
                               const CancellationToken* cancel = nullptr);
// Only the first step of locate_scanner, without the search: the declared position where it could be a
// scanner's and the sampling confirms it, else none (saying why).
ScannerPosition check_declared_scanner(const PointCloud& cloud, const NeighbourAngles& angles);

// Whether a fit says a single constant-angle scanner stood there.
bool fits_a_scanner(const SamplingFit& fit);

}  // namespace k4reg
