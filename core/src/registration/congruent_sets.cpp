#include "k4reg/registration/congruent_sets.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>

#include "k4reg/util/error.h"
#include "k4reg/geometry/neighbor_grid.h"

namespace k4reg {
namespace {

struct Crossing {
  float s = 0, t = 0, distance = INFINITY;
};

// Closest points of segments p + s u and q + t v; distance is infinite unless both lie inside the segments.
Crossing cross_segments(const Eigen::Vector3f& p, const Eigen::Vector3f& u, const Eigen::Vector3f& q,
                        const Eigen::Vector3f& v) {
  const Eigen::Vector3f w = p - q;
  const float a = u.dot(u), b = u.dot(v), c = v.dot(v), d = u.dot(w), e = v.dot(w);
  const float den = a * c - b * b;
  Crossing x;
  if (den <= 1e-9f * a * c) return x;  // parallel diagonals
  x.s = (b * e - c * d) / den;
  x.t = (a * e - b * d) / den;
  // Crossings near a corner make degenerate, nearly triangular bases.
  if (x.s < 0.1f || x.s > 0.9f || x.t < 0.1f || x.t > 0.9f) return x;
  x.distance = (p + x.s * u - q - x.t * v).norm();
  return x;
}

bool in_range(float d, double lo, double hi) { return d >= lo && d <= hi; }

}  // namespace

bool select_base(const std::vector<Eigen::Vector3f>& points, double min_width_m, double max_width_m,
                 double coplanarity_m, std::mt19937_64& rng, Base& base) {
  const std::size_t n = points.size();
  if (n < 4) return false;
  std::uniform_int_distribution<std::size_t> pick(0, n - 1);
  std::vector<std::uint32_t> candidates;
  constexpr int kAttempts = 20, kTriangleTries = 64;
  for (int attempt = 0; attempt < kAttempts; ++attempt) {
    const std::uint32_t a = static_cast<std::uint32_t>(pick(rng));
    candidates.clear();
    for (std::uint32_t k = 0; k < n; ++k)
      if (in_range((points[k] - points[a]).norm(), min_width_m, max_width_m)) candidates.push_back(k);
    if (candidates.size() < 3) continue;
    std::uniform_int_distribution<std::size_t> pick_candidate(0, candidates.size() - 1);
    // The widest triangle among random tries: wide bases give well-conditioned transforms.
    std::uint32_t b = 0, c = 0;
    float best_area = 0;
    for (int t = 0; t < kTriangleTries; ++t) {
      const std::uint32_t i = candidates[pick_candidate(rng)], j = candidates[pick_candidate(rng)];
      if (i == j || !in_range((points[i] - points[j]).norm(), min_width_m, max_width_m)) continue;
      const float area = (points[i] - points[a]).cross(points[j] - points[a]).norm();
      if (area > best_area) best_area = area, b = i, c = j;
    }
    if (best_area == 0) continue;
    // The fourth point: the one whose diagonals come closest to crossing, over the three pairings.
    const std::uint32_t abc[3] = {a, b, c};
    Crossing best;
    std::array<std::uint32_t, 4> best_index{};
    for (std::uint32_t d : candidates) {
      if (d == b || d == c || !in_range((points[d] - points[b]).norm(), min_width_m, max_width_m) ||
          !in_range((points[d] - points[c]).norm(), min_width_m, max_width_m))
        continue;
      for (int pairing = 0; pairing < 3; ++pairing) {
        // Diagonal 1 joins abc[pairing] and d; diagonal 2 joins the other two.
        const std::uint32_t p0 = abc[pairing], p1 = d, p2 = abc[(pairing + 1) % 3], p3 = abc[(pairing + 2) % 3];
        const Crossing x = cross_segments(points[p0], points[p1] - points[p0], points[p2], points[p3] - points[p2]);
        if (x.distance < best.distance) best = x, best_index = {p0, p1, p2, p3};
      }
    }
    if (best.distance > coplanarity_m) continue;
    base.index = best_index;
    for (int k = 0; k < 4; ++k) base.point[k] = points[best_index[k]];
    base.r1 = best.s;
    base.r2 = best.t;
    const Eigen::Vector3f u = base.point[1] - base.point[0], v = base.point[3] - base.point[2];
    base.length1 = u.norm();
    base.length2 = v.norm();
    base.cos_angle = u.dot(v) / (base.length1 * base.length2);
    return true;
  }
  return false;
}

PairIndex::PairIndex(const std::vector<Eigen::Vector3f>& points, double min_m, double max_m,
                     const CancellationToken* cancel, std::size_t max_pairs) {
  const std::size_t n = points.size();
  std::vector<std::vector<Pair>> rows(n);
  std::atomic<std::size_t> collected{0};
  tbb::parallel_for(std::size_t{0}, n, [&](std::size_t i) {
    check(cancel);
    for (std::size_t j = i + 1; j < n; ++j) {
      const float d = (points[i] - points[j]).norm();
      if (in_range(d, min_m, max_m)) rows[i].push_back({d, static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j)});
    }
    if (collected += rows[i].size(); collected > max_pairs)
      fail(ErrorCode::kResourceExhausted,
           "4PCS: more than " + std::to_string(max_pairs) + " target point pairs among " + std::to_string(n) +
               " points; use a larger min_scale_m (or plain_voxel_m for plain 4PCS)");
  });
  std::size_t total = 0;
  for (const auto& row : rows) total += row.size();
  pairs_.reserve(total);
  for (auto& row : rows) {
    pairs_.insert(pairs_.end(), row.begin(), row.end());
    std::vector<Pair>().swap(row);
  }
  // (length, i, j) is a total order, so the sorted index is the same for any thread count.
  tbb::parallel_sort(pairs_.begin(), pairs_.end(), [](const Pair& x, const Pair& y) {
    return x.length != y.length ? x.length < y.length : (x.i != y.i ? x.i < y.i : x.j < y.j);
  });
}

std::pair<const PairIndex::Pair*, const PairIndex::Pair*> PairIndex::with_length(double length, double tolerance) const {
  const auto lo = std::lower_bound(pairs_.begin(), pairs_.end(), static_cast<float>(length - tolerance),
                                   [](const Pair& p, float v) { return p.length < v; });
  const auto hi = std::upper_bound(lo, pairs_.end(), static_cast<float>(length + tolerance),
                                   [](float v, const Pair& p) { return v < p.length; });
  return {pairs_.data() + (lo - pairs_.begin()), pairs_.data() + (hi - pairs_.begin())};
}

void find_congruent_sets(const Base& base, const std::vector<Eigen::Vector3f>& target, const PairIndex& pairs,
                         const CongruenceTolerances& tolerance, std::size_t max_sets, std::vector<Quadrilateral>& out,
                         const CancellationToken* cancel) {
  const auto [first1, last1] = pairs.with_length(base.length1, tolerance.pair_m);
  const auto [first2, last2] = pairs.with_length(base.length2, tolerance.pair_m);
  if (first1 == last1 || first2 == last2) return;

  // Predicted crossings of every diagonal-1 candidate, in both directions (even = i->j, odd = j->i).
  std::vector<Eigen::Vector3f> crossings;
  crossings.reserve(2 * (last1 - first1));
  for (const auto* p = first1; p != last1; ++p) {
    if (((p - first1) & 4095) == 0) check(cancel);
    const Eigen::Vector3f &qi = target[p->i], &qj = target[p->j];
    crossings.push_back(qi + base.r1 * (qj - qi));
    crossings.push_back(qj + base.r1 * (qi - qj));
  }
  const NeighborGrid grid(crossings, tolerance.coincidence_m, NeighborGrid::Queries::kFew);

  float edge[4];  // |p0 p2|, |p0 p3|, |p1 p2|, |p1 p3|
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b) edge[2 * a + b] = (base.point[a] - base.point[2 + b]).norm();
  const float edge_tolerance = static_cast<float>(tolerance.edge_m);
  const float coincidence = static_cast<float>(tolerance.coincidence_m);
  const PairIndex::Pair* const diagonal1 = first1;  // a lambda cannot capture a structured binding before clang 16

  const std::size_t limit = out.size() + max_sets;
  for (const auto* p = first2; p != last2 && out.size() < limit; ++p) {
    if (((p - first2) & 4095) == 0) check(cancel);
    for (int direction = 0; direction < 2; ++direction) {
      const std::uint32_t k = direction ? p->j : p->i, l = direction ? p->i : p->j;
      const Eigen::Vector3f& qk = target[k];
      const Eigen::Vector3f& ql = target[l];
      const Eigen::Vector3f crossing = qk + base.r2 * (ql - qk);
      grid.for_each_within(crossing, coincidence, [&](std::uint32_t c, float) {
        const auto* pair1 = diagonal1 + c / 2;
        const std::uint32_t i = (c & 1) ? pair1->j : pair1->i, j = (c & 1) ? pair1->i : pair1->j;
        if (i == k || i == l || j == k || j == l) return;
        const Eigen::Vector3f &qi = target[i], &qj = target[j];
        if (std::abs((qi - qk).norm() - edge[0]) > edge_tolerance || std::abs((qi - ql).norm() - edge[1]) > edge_tolerance ||
            std::abs((qj - qk).norm() - edge[2]) > edge_tolerance || std::abs((qj - ql).norm() - edge[3]) > edge_tolerance)
          return;
        if (out.size() < limit) out.push_back({i, j, k, l});
      });
    }
  }
}

}  // namespace k4reg
