// The 4PCS search (paper Sec. 2.2): L random bases from the source, their congruent sets in the target,
// a rigid fit per set, verification RANSAC-style. Bases run in parallel in fixed-size batches with a
// random stream per base, so the result is the same for any thread count.
// Cost: one O(n_t^2) pair index (n_t = target points, kept to thousands by keypoints), then per base
// about the number of target pairs matching its two diagonals.
#pragma once

#include <cstdint>
#include <vector>

#include "k4reg/util/cancellation.h"
#include "k4reg/registration/hypothesis.h"

namespace k4reg {

struct FourPcsParams {
  double delta_m = 0.05;  // point precision: every tolerance is a multiple of it
  double overlap = 0.8;
  int max_bases = 0;      // L; 0 = from the overlap
  int hypotheses_kept = 5;
  std::uint64_t seed = 42;
  int verification_points = 1000;  // source points scored per hypothesis
  // Levelled scanners (z axes vertical): every fit is a rotation about z and a translation, so a congruent set
  // that would need a tilt fails the fit tolerance (no out-of-plane flips, fewer sets verified).
  bool levelled = false;
  // Optional, one per point: a congruent set counts only where each target point carries the label of the
  // base point it stands for. The pipeline labels keypoints by their DoG extremum's sign (a bright blob
  // can only be a bright blob in the other scan), which removes most chance sets before verification.
  const std::vector<std::uint8_t>* source_labels = nullptr;
  const std::vector<std::uint8_t>* target_labels = nullptr;
};

struct FourPcsResult {
  std::vector<Hypothesis> hypotheses;  // distinct, best keypoint_score first
  int bases_tried = 0;
  std::size_t congruent_sets = 0;
};

// Number of bases for an overlap, as in PCL's implementation of the paper.
int bases_for_overlap(double overlap);

// Throws kFailedPrecondition when fewer than 4 points are given or no hypothesis is found.
FourPcsResult match_4pcs(const std::vector<Eigen::Vector3f>& source, const std::vector<Eigen::Vector3f>& target,
                         const FourPcsParams& params, const CancellationToken* cancel = nullptr,
                         const ProgressCallback& progress = {});

}  // namespace k4reg
