// The geometric heart of 4PCS (Aiger et al. 2008; paper Sec. 2.2): wide, nearly coplanar 4-point bases
// and the 4-point sets of the other cloud that are congruent to them, found through pair distances and
// the affine-invariant diagonal ratios (paper Eq. 3-4).
// Target pairs are indexed once, sorted by length, so a base costs about the number of pairs that match
// its diagonals rather than a scan over all n^2 pairs (the Super4PCS idea, with sorted lists).
#pragma once

#include <array>
#include <cstdint>
#include <random>
#include <vector>

#include "k4reg/util/cancellation.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace k4reg {

// Every tolerance is a constant multiple of the keypoint precision delta (= the minimum DoG scale),
// never estimated from point density (the paper's central point for keypoints). The factors follow
// PCL's KFPCS, which was written by the paper's first author.
struct CongruenceTolerances {
  double pair_m;          // |pair length - diagonal length|
  double coincidence_m;   // distance between the two predicted diagonal intersections
  double edge_m;          // |edge length - base edge length| for the four outer edges
  double fit_rms_m;       // RMS residual of the rigid fit of the four correspondences
  double coplanarity_m;   // max distance between the two base diagonals
  static CongruenceTolerances from_delta(double delta_m) {
    return {1.414 * delta_m, 2.828 * delta_m, 3.0 * delta_m, 2.0 * delta_m, 1.0 * delta_m};
  }
};

// A 4-point base: diagonals (p0, p1) and (p2, p3) cross at p0 + r1 (p1 - p0) ~ p2 + r2 (p3 - p2).
struct Base {
  std::array<std::uint32_t, 4> index{};
  std::array<Eigen::Vector3f, 4> point;
  float r1 = 0, r2 = 0;
  float length1 = 0, length2 = 0;  // |p1 - p0|, |p3 - p2|
  float cos_angle = 0;             // between the diagonal directions
};

// Draws a wide, nearly coplanar base from points: edges between min_width and max_width, the
// fourth point chosen closest to the plane of the first three. Returns false when none is found.
bool select_base(const std::vector<Eigen::Vector3f>& points, double min_width_m, double max_width_m,
                 double coplanarity_m, std::mt19937_64& rng, Base& base);

// All pairs of target points with length in [min_m, max_m], sorted by length.
class PairIndex {
 public:
  // Throws kResourceExhausted beyond max_pairs pairs (12 bytes each: 360 MB by default) rather than
  // exhaust memory. Cost: O(n^2) distances, in parallel; checks cancel per point.
  static constexpr std::size_t kMaxPairs = 30'000'000;
  PairIndex(const std::vector<Eigen::Vector3f>& points, double min_m, double max_m,
            const CancellationToken* cancel = nullptr, std::size_t max_pairs = kMaxPairs);
  struct Pair {
    float length;
    std::uint32_t i, j;
  };
  // Pairs with length within tolerance of `length`: [first, last).
  std::pair<const Pair*, const Pair*> with_length(double length, double tolerance) const;
  std::size_t size() const { return pairs_.size(); }

 private:
  std::vector<Pair> pairs_;
};

// Correspondence target[match[k]] <-> base.point[k].
using Quadrilateral = std::array<std::uint32_t, 4>;

// Appends the target 4-point sets congruent to base (both diagonal directions tried), at most max_sets:
// dense regular point sets (plain 4PCS on a grid) match combinatorially many, and the caller only
// verifies a bounded subsample anyway.
void find_congruent_sets(const Base& base, const std::vector<Eigen::Vector3f>& target, const PairIndex& pairs,
                         const CongruenceTolerances& tolerance, std::size_t max_sets, std::vector<Quadrilateral>& out,
                         const CancellationToken* cancel = nullptr);

}  // namespace k4reg
