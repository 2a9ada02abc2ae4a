// The symmetry guard (beyond the paper, whose failures were all 180-degree flips of a symmetric room):
// each distinct 4PCS hypothesis is settled by a short coarse ICP and re-scored on the voxelised clouds,
// where the furniture that breaks a room's symmetry is visible: how much of the source the target
// covers, less how much of it lands in space the target scanner saw to be empty (points the target
// scanner could not see, saw from the other side of their surface, or would meet at grazing incidence,
// are no evidence). 4PCS on a symmetric room often finds only the flipped pose, so the best hypothesis's
// twins (and, where the best is not well supported, the runner-up's) under half turns compete too: about
// the target's principal axes through its centre, and about the axes of its normals, shifted to where a
// translation vote on normal-space samples puts them (translation_vote.h). On request (periodic), a twin that wins gets its own twins and, while no hypothesis
// stands out, the best also gets shifted copies at the vote's further peaks: periodic scenes (a corridor's
// doors) repeat under shifts, and 4PCS tends to find the copy that puts one scanner where the other stood.
// Cost per hypothesis (and per twin: nine per round, and up to 48 shifted copies per periodic round): a
// few ICP iterations on a few thousand points from two starts and up to two passes over the coarse
// source; per vote, 1500 x 1500 votes.
#pragma once

#include <vector>

#include "k4reg/util/cancellation.h"
#include "k4reg/registration/free_space.h"
#include "k4reg/registration/icp.h"
#include "k4reg/geometry/neighbor_grid.h"
#include "k4reg/geometry/point_cloud.h"
#include "k4reg/registration/hypothesis.h"

namespace k4reg {

// With free space, a true pose explains 0.95-1.00 of what the target scanner saw on every simulated scene
// (0.4 to 1.5 M points); one that explains less than this is not taken as the truth, however well it beats
// its rivals (the monument's wrong poses where 4PCS had missed the truth: 0.6-0.9).
constexpr double kWellSupportedWithFreeSpace = 0.9;

struct SymmetryGuardResult {
  std::vector<Hypothesis> hypotheses;  // distinct after refinement, best cloud_score first
  double ambiguity_margin = 1.0;       // (best - runner-up) / best; 1 when there is no runner-up
};

// What is known of the two scans' viewpoints (free_space.h: terrestrial scanners' positions, or object views'
// directions; null where the scans do not say): the target's free space and both viewpoints, each in its own
// scan's local frame.
struct ScanViews {
  const FreeSpaceImage* target_free_space = nullptr;
  Viewpoint source;  // in the source's frame
  Viewpoint target;
};

// Source points to score (local frame) and their normals (zero where too few neighbours): free space can
// only contradict a surface the target scanner would have seen, not one it would meet at grazing incidence.
struct ScoredSource {
  std::vector<Eigen::Vector3f> points, normals;
};
// An even subsample of at most max_points of a pyramid stage, with normals from the whole stage.
ScoredSource scored_source(const IcpPyramid::Stage& stage, std::size_t max_points);

// The share of the source that the target explains under t: points with a reference point within tau,
// less those the target scanner saw through, of the points it could see (see symmetry_guard.cpp).
// grid: over reference.points, cells of at least tau.
double cloud_score(const ScoredSource& source, const IcpPyramid::Stage& reference, const NeighborGrid& grid,
                   float tau, const Eigen::Matrix4d& t, const ScanViews* views, double overlap);

// How rank_hypotheses settles and expands the hypotheses.
struct RankingOptions {
  double overlap = 0.0;   // the expected share of the source the target sees (the registration's parameter)
  bool levelled = false;  // the scanners' z axes are vertical: settle by rotations about z, twins turn about z
  // While no hypothesis stands out, also try the best one's shifted copies (for a result the verdict could not
  // decide; the hypotheses are refined already and only scored again): up to 48 more settles.
  bool periodic = false;
};

// Uses the two coarsest levels of the ICP pyramids and scores on the second.
SymmetryGuardResult rank_hypotheses(const IcpPyramid& source, const IcpPyramid& target,
                                    std::vector<Hypothesis> hypotheses, const RankingOptions& options,
                                    const ScanViews* views, const CancellationToken* cancel = nullptr);

}  // namespace k4reg
