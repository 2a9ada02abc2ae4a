#include "k4reg/project/partner_screen.h"

#include <tbb/task_arena.h>

#include <algorithm>
#include <numeric>

#include "k4reg/registration/four_pcs.h"
#include "k4reg/registration/pose_score.h"
#include "k4reg/util/error.h"

namespace k4reg {
namespace {

// The share of the source's surface one screening round of 4PCS brings onto the target's: 4PCS on the keypoints,
// its best poses scored on the voxelised clouds (a keypoint's neighbour is often there by chance on a small or
// busy scene; a surface is not). 0 when no pose is found.
double estimate_overlap(const PreparedScan& source, const PreparedScan& target, const RegistrationParams& params,
                        const CancellationToken* cancel) {
  const double sigma = starting_scale_m(source, target, params.min_scale_m);
  const bool intensity = source.cloud().has_intensity() && target.cloud().has_intensity();
  const DogParams dog{sigma, params.octaves, params.scales_per_octave, params.min_contrast};
  const ScanKeypoints& from = source.keypoints(sigma, params.signal, intensity, dog, cancel);
  const ScanKeypoints& to = target.keypoints(sigma, params.signal, intensity, dog, cancel);
  const double overlap = params.overlap > 0.0 ? params.overlap : kScreenOverlap;
  FourPcsParams four{2.0 * sigma, overlap, kScreenBases, kScreenPoses, params.seed};
  four.levelled = params.levelled;
  four.source_labels = &from.labels;
  four.target_labels = &to.labels;
  FourPcsResult matched;
  try {
    matched = match_4pcs(from.points, to.points, four, cancel);
  } catch (const Error& e) {
    if (e.code() != ErrorCode::kFailedPrecondition) throw;
    return 0.0;  // too few keypoints, or no pose
  }
  // The pyramids the pair's registration uses at this scale (made once per scan).
  IcpParams icp;
  icp.voxel_m = sigma;
  icp.max_iterations = params.icp_max_iterations;
  icp.levelled = params.levelled;
  const PoseScorer scorer(source.pyramid(sigma, icp, PyramidRole::kSource, cancel),
                          target.pyramid(sigma, icp, PyramidRole::kTarget, cancel), nullptr, overlap);
  double best = 0.0;
  for (const Hypothesis& h : matched.hypotheses) best = std::max(best, scorer.score(h.transform));
  return best;
}

// Indices into `all`, best estimate first (then the lower pair: a fixed order).
std::vector<std::size_t> best_first(const std::vector<ScanPair>& all, const std::vector<double>& estimates) {
  if (estimates.size() != all.size())
    fail(ErrorCode::kInvalidArgument, "one overlap estimate per pair of scans expected");
  std::vector<std::size_t> order(all.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return estimates[a] > estimates[b]; });
  return order;
}

// Union-find over scan indices.
std::size_t root(std::vector<std::size_t>& parent, std::size_t i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

}  // namespace

std::vector<double> estimate_overlaps(const std::vector<PreparedScan>& scans, const RegistrationParams& params,
                                      const CancellationToken* cancel, const ProgressCallback& progress) {
  const std::vector<ScanPair> pairs = candidate_pairs(scans.size(), PairSelection::kAll);
  std::vector<double> estimates(pairs.size(), 0.0);
  tbb::task_arena arena(params.threads > 0 ? params.threads : tbb::task_arena::automatic);
  arena.execute([&] {
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      check(cancel);
      estimates[k] = estimate_overlap(scans[pairs[k].first], scans[pairs[k].second], params, cancel);
      if (progress) progress("screen", static_cast<double>(k + 1) / pairs.size());
    }
  });
  return estimates;
}

std::vector<ScanPair> best_partners(std::size_t scans, const std::vector<double>& estimates, std::size_t partners) {
  const std::vector<ScanPair> all = candidate_pairs(scans, PairSelection::kAll);
  const std::vector<std::size_t> order = best_first(all, estimates);

  std::vector<bool> chosen(all.size(), false);
  // Best first, so each scan takes its own `partners` best (a pair one scan takes need not be among the other's).
  std::vector<std::size_t> taken(scans, 0);
  for (std::size_t k : order)
    for (std::size_t scan : {all[k].first, all[k].second})
      if (taken[scan] < partners) ++taken[scan], chosen[k] = true;
  // Then the best pairs that join what is still apart.
  std::vector<std::size_t> parent(scans);
  std::iota(parent.begin(), parent.end(), 0);
  for (std::size_t k = 0; k < all.size(); ++k)
    if (chosen[k]) parent[root(parent, all[k].first)] = root(parent, all[k].second);
  for (std::size_t k : order) {
    const std::size_t a = root(parent, all[k].first), b = root(parent, all[k].second);
    if (a != b) parent[a] = b, chosen[k] = true;
  }
  std::vector<ScanPair> pairs;
  for (std::size_t k = 0; k < all.size(); ++k)
    if (chosen[k]) pairs.push_back(all[k]);
  return pairs;
}

std::vector<ScanPair> more_partners(std::size_t scans, const std::vector<double>& estimates,
                                    const std::vector<ScanPair>& chosen, const std::vector<std::size_t>& extend,
                                    std::size_t partners) {
  const std::vector<ScanPair> all = candidate_pairs(scans, PairSelection::kAll);
  const std::vector<std::size_t> order = best_first(all, estimates);
  std::vector<ScanPair> more;
  for (std::size_t scan : extend) {
    std::size_t taken = 0;
    for (std::size_t k : order) {
      if (taken == partners) break;
      if (all[k].first != scan && all[k].second != scan) continue;
      if (std::find(chosen.begin(), chosen.end(), all[k]) != chosen.end()) continue;
      ++taken;
      more.push_back(all[k]);
    }
  }
  std::sort(more.begin(), more.end());
  more.erase(std::unique(more.begin(), more.end()), more.end());
  return more;
}

}  // namespace k4reg
