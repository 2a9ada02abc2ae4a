// Point-to-plane ICP with a Geman-McClure kernel, coarse to fine over voxel grids (e.g. 4, 2, 1 x the
// finest spacing), each stage iterated until the update is negligible. Deterministic reductions.
// The target side (downsampled clouds, normals, neighbour grids) is prepared once and can serve many
// refinements, e.g. one per hypothesis. Cost per iteration: O(source points) neighbour look-ups.
#pragma once

#include <memory>
#include <vector>

#include "k4reg/util/cancellation.h"
#include "k4reg/geometry/neighbor_grid.h"
#include "k4reg/geometry/point_cloud.h"

namespace k4reg {

struct IcpParams {
  double voxel_m = 0.05;             // finest stage spacing
  int stages = 3;                    // spacings voxel_m * 2^(stages-1) ... voxel_m
  int max_iterations = 50;           // per stage
  double max_distance_factor = 2.5;  // correspondences within this many stage voxels
  bool levelled = false;             // only rotations about z (and translations): 4 unknowns, not 6
  bool finest_stage_only = false;    // polish a pose already refined on the coarser stages
  // A stage has converged once a step moves the cloud by less than this many stage voxels (and turns it by less
  // than a hundredth of that in radians).
  double converged_step_voxels = 1e-4;
  // One more pass at the end for the fit figures (rmse_m, overlap, inliers, translation_information); callers that
  // keep only the pose (the symmetry guard's settling, the contenders, the fine polish's finer stage) skip it.
  bool measure_fit = true;
};

// Converged enough to compare poses (the symmetry guard, contenders for the verdict); a winner is polished after.
constexpr double kSettledStepVoxels = 1e-2;

struct IcpResult {
  Eigen::Matrix4d transform = Eigen::Matrix4d::Identity();
  double rmse_m = 0.0;   // RMS point-to-plane residual of the final inliers
  double overlap = 0.0;  // share of source points with a target point within the final distance
  std::size_t inliers = 0;
  // The final inliers' translation information Sum w n n^T (target frame): how the surfaces pin each direction
  // (translation_constraint.h).
  Eigen::Matrix3d translation_information = Eigen::Matrix3d::Zero();
  bool converged = false;
  int iterations = 0;
};

// One cloud at every stage spacing, coarsest first; the target also gets normals and a grid.
struct IcpPyramid {
  struct Stage {
    double voxel_m = 0.0;
    std::vector<Eigen::Vector3f> points;
    std::vector<Eigen::Vector3f> normals;  // target only
    std::unique_ptr<NeighborGrid> grid;    // target only
  };
  std::vector<Stage> stages;
};

// Which side of a registration a pyramid serves: the target's stages carry neighbour grids and normals
// (add_target_search), which cost a grid build and a PCA per point; the source's need neither.
enum class PyramidRole { kSource, kTarget };

// points: at spacing params.voxel_m (coarser stages are voxelised from them).
IcpPyramid make_icp_pyramid(const std::vector<Eigen::Vector3f>& points, const IcpParams& params, PyramidRole role,
                            const CancellationToken* cancel = nullptr);
// Every k-th point, at most max_points of them: an even subsample of a voxelised cloud, in its order.
std::vector<Eigen::Vector3f> every_kth(const std::vector<Eigen::Vector3f>& points, std::size_t max_points);
// every_kth of each stage, at most max_points per stage (a source for ICP: no grids, no normals).
// A pose needs thousands of well-spread correspondences; ICP's cost is linear in them.
IcpPyramid thin_pyramid(const IcpPyramid& pyramid, std::size_t max_points);
// Adds the neighbour grids and normals to a pyramid made without them (the same as making it as PyramidRole::kTarget).
void add_target_search(IcpPyramid& pyramid, const IcpParams& params, const CancellationToken* cancel = nullptr);

IcpResult refine_icp(const IcpPyramid& source, const IcpPyramid& target, const Eigen::Matrix4d& initial,
                     const IcpParams& params, const CancellationToken* cancel = nullptr);

// Normals by local PCA with neighbours within radius_m (grid: over `points`, cells of about radius_m or
// more); zero where fewer than 3 neighbours.
std::vector<Eigen::Vector3f> estimate_normals(const std::vector<Eigen::Vector3f>& points, const NeighborGrid& grid,
                                              double radius_m);
// The same at `queries`, from the neighbours among `points`.
std::vector<Eigen::Vector3f> estimate_normals(const std::vector<Eigen::Vector3f>& queries,
                                              const std::vector<Eigen::Vector3f>& points, const NeighborGrid& grid,
                                              double radius_m);

}  // namespace k4reg
