// Global refinement of scan poses over pairwise links: the one least-squares solver of project
// registration, behind this small interface. Levenberg-Marquardt on SE(3) with Eigen's sparse LDLT (Eigen
// only, so builds stay licence-clean: Debian's Ceres links GPL-2+ parts of SuiteSparse) and a Huber kernel,
// so one link that survived the loop checks but disagrees with the rest bends the graph little.
// Each link residual is the 6-vector [radius * rotation; displacement of the centre] of the transform that should be
// the identity (the `from` scan's extent), so rotation and translation both count in metres of scan displacement,
// measured where the scan is rather than at its file's origin.
// Cost: per iteration O(links) residuals and a sparse factorisation of 6(N-1) unknowns (N = scans):
// milliseconds for hundreds of scans, next to seconds per pairwise registration.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "k4reg/geometry/rigid_motion.h"

namespace k4reg {

struct PoseGraphLink {
  std::size_t from = 0, to = 0;          // scan indices
  Eigen::Matrix4d measured = Eigen::Matrix4d::Identity();  // p_to = measured * p_from (scan frames)
  ScanExtent from_extent{Eigen::Vector3d::Zero(), 1.0};  // where the `from` scan's points lie (its frame)
  double weight = 1.0;       // relative confidence (> 0)
};

struct PoseGraphParams {
  std::size_t fixed = 0;       // the scan whose pose stays as given (the project's reference)
  double huber_m = 0.0;        // residuals beyond this many metres are down-weighted; 0 = plain least squares
  int max_iterations = 100;
  bool levelled = false;       // poses change by rotations about the project's z axis only (levelled scanners)
};

struct PoseGraphResult {
  std::vector<Eigen::Matrix4d> poses;  // p_project = pose * p_scan
  std::vector<double> residual_m;      // per link, after refinement: displacement_m of the link's misfit
  int iterations = 0;
  double initial_cost = 0.0, final_cost = 0.0;  // sum of weighted squared residuals (m^2)
};

// Refines `initial` (one pose per scan; every scan a link touches must be connected to `fixed`, or its
// pose stays undetermined up to the solver's damping). Deterministic.
PoseGraphResult optimize_pose_graph(const std::vector<Eigen::Matrix4d>& initial,
                                    const std::vector<PoseGraphLink>& links, const PoseGraphParams& params);

// optimize_pose_graph, then again from its poses with the kernel at twice the median link residual, as long as
// that scale shrinks clearly below the last (at most four times): a link that the loops let through but that sits
// several times further off than the rest (a pose its loops implied, refined on a narrow overlap: 8 mm where the
// others show 1 mm on a simulated statuette) then bends the graph little. The kernel's first scale is a tolerance;
// the later ones, what the links show. Fewer than 3 links: one solve. Cost: up to five solves.
PoseGraphResult optimize_pose_graph_robustly(const std::vector<Eigen::Matrix4d>& initial,
                                             const std::vector<PoseGraphLink>& links, const PoseGraphParams& params);

// The misfit of a link under the given poses (identity when they agree): measured^-1 * to^-1 * from.
Eigen::Matrix4d link_misfit(const Eigen::Matrix4d& from_pose, const Eigen::Matrix4d& to_pose,
                            const Eigen::Matrix4d& measured);

}  // namespace k4reg
