// The verdict on the symmetry guard's ranking: the leading hypotheses (the contenders) refined fully and judged
// again, on the share of the source they explain once refined and on whether they lie on the target surface.
// Cost: one ICP per contender on a thinned source (at most 3, side by side) and one scoring of each.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "k4reg/registration/hypothesis.h"
#include "k4reg/registration/icp.h"
#include "k4reg/registration/pose_score.h"
#include "k4reg/registration/prepared_scan.h"
#include "k4reg/registration/symmetry_guard.h"
#include "k4reg/util/cancellation.h"
#include "k4reg/util/stage_timing.h"

namespace k4reg {

// A refined pose with less surface agreement than this share of what the target's own two halves reach
// (PreparedScan::surface_self_agreement: 0.99 or more on clean scans, less on noisy ones) is not taken as well
// supported.
constexpr double kMinSurfaceAgreement = 0.75;

// Hypotheses whose cloud score is within this share of the best are contenders: refined fully and judged again.
constexpr double kContenderBand = 0.2;

// The surface agreement a refined pose needs to count as lying on the target surface: kMinSurfaceAgreement of
// what the target's own two halves reach (no pose can do better than two samplings of one surface). On clean
// scans they reach 0.99 or more, so the bar is kMinSurfaceAgreement itself; noise or clutter at the scale
// lowers both (a 2D scanner swept through an office, cm noise at a 5 cm scale: 0.75). Measured only for a
// pose under kMinSurfaceAgreement.
class SurfaceBar {
 public:
  SurfaceBar(const PreparedScan& target, double sigma_m, const CancellationToken* cancel)
      : target_(target), sigma_m_(sigma_m), cancel_(cancel) {}
  bool passes(double agreement) const { return agreement >= kMinSurfaceAgreement || agreement >= required(); }
  double required() const {
    if (required_ < 0.0) required_ = kMinSurfaceAgreement * target_.surface_self_agreement(sigma_m_, cancel_);
    return required_;
  }

 private:
  const PreparedScan& target_;
  double sigma_m_;
  const CancellationToken* cancel_;
  mutable double required_ = -1.0;
};

// The verdict on the guard's ranking: the leading hypotheses refined fully and judged again.
struct Verdict {
  std::vector<Hypothesis> hypotheses;  // the winner first, the other contenders after it, the rest as they were
  double margin = 1.0;                 // (winner - runner-up) / winner, on the refined scores
  bool on_surface = true;              // whether the winner lies on the target surface
  int iterations = 0;                  // the winner's ICP iterations
  // The surface agreement of a contender that lies clearly more on the target surface than the winner (by
  // kAmbiguousMargin of its own) while nearly as well supported; 0 where none does. The two figures then
  // disagree: a periodic scene's shifted copy can explain as much of the source as the truth (the corridor's
  // doors, free space seen the same from either station) yet fits its surfaces less closely.
  double disputed_by = 0.0;
};

// What the contenders are judged with.
struct ContenderJudging {
  const IcpPyramid& source;
  const IcpPyramid& target;
  const PoseScorer& scorer;  // the share of the source a pose explains, and how much of it lies on the surface
  const SurfaceBar& bar;
  IcpParams final_params;    // the full refinement's
  bool refine = true;        // false (--no-icp): contenders are scored where the guard left them, not on the surface
  double sigma_m = 0.0;      // poses closer than 2 sigma_m are one
};

// The contenders refined ("icp") and judged ("verdict"), each stage timed by `stages`.
Verdict judge_contenders(const SymmetryGuardResult& guarded, const ContenderJudging& judging, StageRunner& stages,
                         const CancellationToken* cancel);

}  // namespace k4reg
