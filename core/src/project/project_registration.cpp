#include "k4reg/project/project_registration.h"

#include <fmt/format.h>

#include "k4reg/geometry/rigid_motion.h"
#include "k4reg/geometry/sampling.h"
#include "k4reg/project/link_judging.h"
#include "k4reg/project/pair_stage.h"
#include "k4reg/project/placement.h"
#include "k4reg/util/error.h"

namespace k4reg {
namespace {

void validate(const std::vector<PointCloud>& scans, const ProjectParams& params) {
  validate(params.pairwise);
  if (scans.size() < 2)
    fail(ErrorCode::kInvalidArgument, fmt::format("a project needs at least 2 scans, got {}", scans.size()));
  if (params.reference >= scans.size())
    fail(ErrorCode::kInvalidArgument,
         fmt::format("reference scan {} is out of range: the project has {} scans (indices start at 0)", params.reference,
                     scans.size()));
  for (std::size_t i = 0; i < scans.size(); ++i)
    if (scans[i].empty()) fail(ErrorCode::kInvalidArgument, fmt::format("scan {} is empty", i));
  if (params.partners == 0) fail(ErrorCode::kInvalidArgument, "partners must be at least 1");
}

// Where a scan's points lie, in its file's frame: their centroid and, as the radius a rotation error moves them
// by, the robust diameter (the centroid lies within the 2nd..98th percentile box, so no corner of it is farther;
// stray far returns do not count).
std::vector<ScanExtent> extents_of(const std::vector<PointCloud>& scans) {
  std::vector<ScanExtent> extents;
  for (const PointCloud& cloud : scans) extents.push_back({centroid(cloud.points) + cloud.origin_m, robust_diameter(cloud.points)});
  return extents;
}

// The parameters each pair runs with: the project's deadline covers every pair, and the project searches the pairs
// of scans no loop confirms from the other side itself (pair_stage.h).
RegistrationParams pairwise_params(const ProjectParams& params) {
  RegistrationParams pairwise = params.pairwise;
  pairwise.time_budget_s = 0.0;
  pairwise.search_other_side = false;
  return pairwise;
}

}  // namespace

ProjectResult register_project(const std::vector<PointCloud>& scans, const ProjectParams& params,
                               const CancellationToken* cancel, const ProgressCallback& progress,
                               const PairCallback& on_pair, PairRunner* runner) {
  validate(scans, params);
  CancellationToken budget(cancel);
  if (params.pairwise.time_budget_s > 0) budget.set_deadline(deadline_in(params.pairwise.time_budget_s));
  // Each scan's voxels, keypoints and pyramids are computed once, in its first pair, and shared by the rest.
  const std::vector<PreparedScan> prepared(scans.begin(), scans.end());
  const std::vector<ScanExtent> extents = extents_of(scans);
  const RegistrationParams pairwise = pairwise_params(params);
  const ProjectInputs in{prepared, extents, pairwise, &budget, progress};

  ProjectResult r;
  r.reference = params.reference;
  r.scans.resize(scans.size());
  for (std::size_t i = 0; i < scans.size(); ++i) r.scans[i].points = scans[i].size();

  const RegisteredPairs registered = register_pairs(in, params, on_pair, runner, r);
  std::vector<LinkCandidates> candidates = links_of_pairs(registered, r);
  if (progress) progress("selection", 0.0);
  judge_weak_links_from_both_sides(in, registered.pairs, candidates, r);
  judge_poses_open_loops_imply(in, registered.pairs, candidates, r);
  select_links(candidates, registered.pairs, extents, r);
  if (progress) progress("selection", 1.0);
  place_and_refine(in, candidates, params.pairwise.levelled, r);
  // As the pairs judged them where they ran here; else (pairs run on peers) what is known without a search.
  for (std::size_t i = 0; i < r.scans.size(); ++i) r.scans[i].scanner_position = prepared[i].scanner_known(&budget);
  if (progress) progress("refinement", 1.0);
  return r;
}

}  // namespace k4reg
