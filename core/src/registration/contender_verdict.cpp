#include "k4reg/registration/contender_verdict.h"

#include <tbb/parallel_for.h>

#include <algorithm>

#include "k4reg/geometry/rigid_motion.h"
#include "k4reg/registration/ambiguity_margin.h"

namespace k4reg {
namespace {

constexpr std::size_t kMaxContenders = 3;
constexpr std::size_t kContenderPoints = 15000;  // per ICP stage: a pose to well under a voxel

}  // namespace

Verdict judge_contenders(const SymmetryGuardResult& guarded, const ContenderJudging& judging, StageRunner& stages,
                         const CancellationToken* cancel) {
  const IcpPyramid &source = judging.source, &target = judging.target;
  const PoseScorer& scorer = judging.scorer;
  const SurfaceBar& bar = judging.bar;
  const bool icp = judging.refine;
  Verdict verdict;
  verdict.hypotheses = guarded.hypotheses;
  verdict.margin = guarded.ambiguity_margin;
  std::vector<Hypothesis>& hypotheses = verdict.hypotheses;
  std::size_t contenders = 1;
  while (contenders < std::min(kMaxContenders, hypotheses.size()) &&
         hypotheses[contenders].cloud_score >= (1.0 - kContenderBand) * hypotheses.front().cloud_score)
    ++contenders;
  // Only contenders carry refined figures (hypotheses judged before may come back from a wider search).
  for (std::size_t i = contenders; i < hypotheses.size(); ++i) hypotheses[i].refined_score = hypotheses[i].surface_agreement = 0.0;
  // Contenders refine on a thinned source, side by side (each sum is deterministic); the winner is then
  // polished on every point at the finest stage, which also gives its quality figures.
  const IcpPyramid contender_source = thin_pyramid(source, kContenderPoints);
  const Eigen::Vector3d source_centre = centroid(source.stages.front().points);  // where poses are compared
  IcpParams contender_params = judging.final_params;
  contender_params.converged_step_voxels = kSettledStepVoxels;
  contender_params.measure_fit = false;  // scored below
  std::vector<IcpResult> refined(contenders);
  stages.run("icp", [&] {
    tbb::parallel_for(std::size_t{0}, contenders, [&](std::size_t i) {
      refined[i] = refine_icp(contender_source, target, hypotheses[i].transform, contender_params, cancel);
    });
    return 0;
  });
  // Per contender: the share of the source the target explains once refined, and how much of what comes
  // near the target surface lies on it. Contenders that refined into an earlier one's pose drop out.
  std::vector<std::size_t> kept;
  stages.run("verdict", [&] {
    tbb::parallel_for(std::size_t{0}, contenders, [&](std::size_t i) {
      Hypothesis& h = hypotheses[i];
      if (icp) h.transform = refined[i].transform;
      h.refined_score = scorer.score(h.transform);
      if (icp) h.surface_agreement = scorer.surface_agreement(h.transform);
    });
    for (std::size_t i = 0; i < contenders; ++i)
      if (std::none_of(kept.begin(), kept.end(), [&](std::size_t k) {
            return !distinct_transforms(hypotheses[k].transform, hypotheses[i].transform, source_centre, 2.0,
                                        2.0 * judging.sigma_m);
          }))
        kept.push_back(i);
    return 0;
  });
  // A pose off the target surface cannot be the true one, however well supported: contenders on the
  // surface rank first, then by support (unrefined poses, with --no-icp, are not judged on the surface).
  auto on_surface = [&](std::size_t i) { return !icp || bar.passes(hypotheses[i].surface_agreement); };
  std::stable_sort(kept.begin(), kept.end(), [&](std::size_t a, std::size_t b) {
    if (on_surface(a) != on_surface(b)) return on_surface(a);
    return hypotheses[a].refined_score > hypotheses[b].refined_score;
  });
  const std::size_t winner = kept[0];
  verdict.on_surface = on_surface(winner);
  verdict.iterations = refined[winner].iterations;
  // The runner-up is the next contender of the winner's kind; failing one, the best unrefined hypothesis.
  const auto rival = std::find_if(kept.begin() + 1, kept.end(), [&](std::size_t i) { return on_surface(i) == verdict.on_surface; });
  const double winner_score = hypotheses[winner].refined_score;
  for (std::size_t i : kept)
    if (icp && on_surface(i) && hypotheses[i].refined_score >= (1.0 - kContenderBand) * winner_score &&
        hypotheses[i].surface_agreement * (1.0 - kAmbiguousMargin) > hypotheses[winner].surface_agreement)
      verdict.disputed_by = std::max(verdict.disputed_by, hypotheses[i].surface_agreement);
  if (rival != kept.end())
    verdict.margin = winner_score > 0 ? std::clamp((winner_score - hypotheses[*rival].refined_score) / winner_score, 0.0, 1.0) : 0.0;
  else if (contenders > 1)
    verdict.margin = contenders < hypotheses.size()
                         ? std::clamp(1.0 - hypotheses[contenders].cloud_score / hypotheses[winner].cloud_score, 0.0, 1.0)
                         : 1.0;
  std::vector<Hypothesis> reordered;
  for (std::size_t i : kept) reordered.push_back(hypotheses[i]);
  reordered.insert(reordered.end(), hypotheses.begin() + contenders, hypotheses.end());
  hypotheses = std::move(reordered);
  return verdict;
}

}  // namespace k4reg
