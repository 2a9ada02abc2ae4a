#include "k4reg/registration/four_pcs.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "k4reg/registration/congruent_sets.h"
#include "k4reg/util/error.h"
#include "k4reg/geometry/neighbor_grid.h"
#include "k4reg/geometry/rigid_fit.h"
#include "k4reg/geometry/rigid_motion.h"
#include "k4reg/geometry/sampling.h"

namespace k4reg {
namespace {

constexpr int kBatch = 8;               // bases per parallel batch (fixed: determinism)
constexpr int kPrescreenPoints[] = {20, 40, 200};  // cheap looks before a full verification
constexpr std::size_t kMaxSetsPerBase = 20000;     // verified per base (an even subsample)
constexpr std::size_t kMaxSetsFound = 8 * kMaxSetsPerBase;  // collected per base: bounds memory and time
constexpr double kInlierFactor = 3.0;   // inlier distance in units of delta

// MSAC-style score: each point contributes 1 - d^2/tau^2 when within tau of a target point. (Free space
// is left to the symmetry guard, which scores whole clouds; keypoints are too few to profit from it.)
class Verifier {
 public:
  Verifier(const std::vector<Eigen::Vector3f>& source, const std::vector<Eigen::Vector3f>& target, double tau_m,
           int max_points, std::uint64_t seed)
      : grid_(target, 2.0 * tau_m), tau_(static_cast<float>(tau_m)) {  // 8-cell look-ups
    std::vector<std::uint32_t> order(source.size());
    std::iota(order.begin(), order.end(), 0);
    std::mt19937_64 rng(seed);
    std::shuffle(order.begin(), order.end(), rng);
    order.resize(std::min<std::size_t>(order.size(), max_points));
    for (std::uint32_t i : order) points_.push_back(source[i]);
  }

  std::size_t size() const { return points_.size(); }

  // Score over points [0, count), stopping early once it cannot reach `beat`.
  double score(const Eigen::Matrix4d& t, std::size_t count, double beat) const {
    const Eigen::Affine3f a = to_affine3f(t);
    const float inv_tau2 = 1.0f / (tau_ * tau_);
    double s = 0;
    for (std::size_t k = 0; k < count; ++k) {
      float d2 = 0;
      const Eigen::Vector3f q = a * points_[k];
      if (grid_.nearest_within(q, tau_, &d2) >= 0) s += 1.0 - d2 * inv_tau2;
      if (s + static_cast<double>(count - k - 1) < beat) return -1.0;
    }
    return s;
  }

 private:
  NeighborGrid grid_;
  float tau_;
  std::vector<Eigen::Vector3f> points_;
};

// Whether the score over each prescreen's first points, scaled to all points, reaches `needed`.
bool passes_prescreens(const Verifier& verifier, const Eigen::Matrix4d& t, double needed) {
  for (const int points : kPrescreenPoints) {
    if (static_cast<std::size_t>(points) >= verifier.size()) return true;
    const double threshold = needed * points / verifier.size();
    if (verifier.score(t, points, threshold) < threshold) return false;
  }
  return true;
}

struct Candidate {
  double score = 0;
  Eigen::Matrix4d transform = Eigen::Matrix4d::Identity();
  Eigen::Matrix<float, 3, 4> base, set;  // the base's points and the congruent set's, kept for the QA report
};

// The best few distinct candidates of one base. A base of a symmetric scene matches both the true
// pose and its mirror image; keeping only the best would let the mirror crowd the truth out.
struct BaseOutcome {
  static constexpr std::size_t kKept = 3;
  std::vector<Candidate> candidates;  // best first
  std::size_t sets = 0;

  // Score a newcomer must beat to matter.
  double floor() const { return candidates.size() < kKept ? 0.0 : candidates.back().score; }

  void offer(const Candidate& c, const Eigen::Vector3d& centre, double min_angle_deg, double min_translation_m) {
    auto same = std::find_if(candidates.begin(), candidates.end(), [&](const Candidate& k) {
      return !distinct_transforms(k.transform, c.transform, centre, min_angle_deg, min_translation_m);
    });
    if (same != candidates.end()) {
      if (c.score <= same->score) return;
      candidates.erase(same);
    }
    candidates.insert(std::upper_bound(candidates.begin(), candidates.end(), c,
                                       [](const Candidate& a, const Candidate& b) { return a.score > b.score; }),
                      c);
    if (candidates.size() > kKept) candidates.pop_back();
  }
};

constexpr double kDistinctAngle_deg = 10.0;
constexpr double kDistinctShiftDeltas = 10.0;

}  // namespace

int bases_for_overlap(double overlap) {
  const double o = std::clamp(overlap, 0.05, 1.0);
  const double first_estimate = std::log(1e-5) / std::log(std::max(1e-12, 1.0 - std::pow(o, 4)));
  return std::max(4, static_cast<int>(std::ceil(first_estimate / (0.3 * 2.0 * o))));
}

FourPcsResult match_4pcs(const std::vector<Eigen::Vector3f>& source, const std::vector<Eigen::Vector3f>& target,
                         const FourPcsParams& params, const CancellationToken* cancel, const ProgressCallback& progress) {
  if (source.size() < 4 || target.size() < 4)
    fail(ErrorCode::kFailedPrecondition, "4PCS needs at least 4 points per cloud (got " + std::to_string(source.size()) +
                                             " and " + std::to_string(target.size()) + ")");
  const CongruenceTolerances tolerance = CongruenceTolerances::from_delta(params.delta_m);
  // Bases as wide as the overlap allows (paper: from the overlap and the diameter), but not so narrow
  // that the rotation is poorly determined.
  const double max_width = std::max(params.overlap * robust_diameter(source), 10.0 * params.delta_m);
  const double min_width = std::max(0.1 * max_width, 4.0 * params.delta_m);
  const PairIndex pairs(target, min_width - tolerance.pair_m, max_width + tolerance.pair_m, cancel);
  const Verifier verifier(source, target, kInlierFactor * params.delta_m, params.verification_points, params.seed);
  const Eigen::Vector3d centre = centroid(source);  // where poses are compared
  const int bases = params.max_bases > 0 ? params.max_bases : bases_for_overlap(params.overlap);
  const bool labelled = params.source_labels && params.target_labels;
  if (labelled && (params.source_labels->size() != source.size() || params.target_labels->size() != target.size()))
    fail(ErrorCode::kInvalidArgument, "4PCS: one label per point is needed");

  // Every base's best few candidates (with or without the labels).
  auto search = [&](bool use_labels) {
    std::vector<BaseOutcome> outcomes(bases);
    double global_best = 0;  // from finished batches only, so pruning does not depend on timing
    for (int start = 0; start < bases; start += kBatch) {
      check(cancel);
      const int end = std::min(bases, start + kBatch);
      tbb::parallel_for(start, end, [&](int b) {
        std::seed_seq seq{static_cast<std::uint64_t>(params.seed), static_cast<std::uint64_t>(b)};
        std::mt19937_64 rng(seq);
        Base base;
        if (!select_base(source, min_width, max_width, tolerance.coplanarity_m, rng, base)) return;
        std::vector<Quadrilateral> sets;
        find_congruent_sets(base, target, pairs, tolerance, kMaxSetsFound, sets, cancel);
        if (use_labels)
          std::erase_if(sets, [&](const Quadrilateral& set) {
            for (int k = 0; k < 4; ++k)
              if ((*params.target_labels)[set[k]] != (*params.source_labels)[base.index[k]]) return true;
            return false;
          });
        BaseOutcome& out = outcomes[b];
        out.sets = sets.size();
        // Dense, regular point sets (the plain-4PCS baseline on a grid) give combinatorially many sets;
        // an even subsample keeps a base's cost bounded.
        if (sets.size() > kMaxSetsPerBase) {
          const std::size_t stride = (sets.size() + kMaxSetsPerBase - 1) / kMaxSetsPerBase;
          for (std::size_t k = 0; k * stride < sets.size(); ++k) sets[k] = sets[k * stride];
          sets.resize((sets.size() + stride - 1) / stride);
        }
        Eigen::Matrix3Xd from(3, 4), to(3, 4);
        for (int k = 0; k < 4; ++k) from.col(k) = base.point[k].cast<double>();
        for (std::size_t s = 0; s < sets.size(); ++s) {
          if ((s & 255) == 0) check(cancel);
          for (int k = 0; k < 4; ++k) to.col(k) = target[sets[s][k]].cast<double>();
          const Eigen::Matrix4d t = params.levelled ? fit_rigid_about_z(from, to) : fit_rigid(from, to);
          if (fit_rms(t, from, to) > tolerance.fit_rms_m) continue;
          const double beat = std::max(out.floor(), global_best);
          // Prescreens on the first points: a hypothesis far below the best so far is not worth a full look.
          if (!passes_prescreens(verifier, t, 0.5 * beat)) continue;
          const double full = verifier.score(t, verifier.size(), std::max(out.floor(), 0.5 * global_best));
          if (full > out.floor() && full > 0)
            out.offer({full, t, from.cast<float>(), to.cast<float>()}, centre, kDistinctAngle_deg,
                      kDistinctShiftDeltas * params.delta_m);
        }
      });
      for (int b = start; b < end; ++b)
        if (!outcomes[b].candidates.empty()) global_best = std::max(global_best, outcomes[b].candidates.front().score);
      if (progress) progress("matching", double(end) / bases);
    }
    return outcomes;
  };
  std::vector<BaseOutcome> outcomes = search(labelled);
  // A handful of keypoints (a small object at a coarse scale) may give no set whose labels agree: chance
  // sets still give a rough pose that the symmetry guard's ICP can settle, so they get their turn.
  const auto found = [](const BaseOutcome& o) { return !o.candidates.empty(); };
  if (labelled && std::none_of(outcomes.begin(), outcomes.end(), found)) outcomes = search(false);

  // Distinct hypotheses over all bases, best first (ties to the earlier base: deterministic order).
  std::vector<Candidate> all;
  FourPcsResult result;
  result.bases_tried = bases;
  for (const BaseOutcome& outcome : outcomes) {
    result.congruent_sets += outcome.sets;
    all.insert(all.end(), outcome.candidates.begin(), outcome.candidates.end());
  }
  std::stable_sort(all.begin(), all.end(), [](const Candidate& a, const Candidate& b) { return a.score > b.score; });
  for (const Candidate& c : all) {
    if (static_cast<int>(result.hypotheses.size()) >= params.hypotheses_kept) break;
    const bool is_new = std::all_of(result.hypotheses.begin(), result.hypotheses.end(), [&](const Hypothesis& h) {
      return distinct_transforms(h.transform, c.transform, centre, kDistinctAngle_deg,
                                 kDistinctShiftDeltas * params.delta_m);
    });
    if (!is_new) continue;
    Hypothesis h;
    h.transform = c.transform;
    h.keypoint_score = c.score / verifier.size();
    for (int k = 0; k < 4; ++k) {
      h.base_source_m.push_back(c.base.col(k).cast<double>());
      h.base_target_m.push_back(c.set.col(k).cast<double>());
    }
    result.hypotheses.push_back(h);
  }
  if (result.hypotheses.empty())
    fail(ErrorCode::kFailedPrecondition, "no alignment found: no congruent 4-point set among " + std::to_string(bases) +
                                             " bases (is the overlap or the minimum scale right?)");
  return result;
}

}  // namespace k4reg
