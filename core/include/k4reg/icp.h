// Point-to-plane ICP with a Geman-McClure kernel, coarse to fine over voxel grids (e.g. 4, 2, 1 x the
// finest spacing), each stage iterated until the update is negligible. Deterministic reductions.
// Cost per iteration: O(source points) neighbour look-ups.
#pragma once

#include <vector>

#include "k4reg/cancellation.h"
#include "k4reg/point_cloud.h"

namespace k4reg {

struct IcpParams {
  double voxel_m = 0.05;        // finest stage spacing
  int stages = 3;               // spacings voxel_m * 2^(stages-1) ... voxel_m
  int max_iterations = 50;      // per stage
  double max_distance_factor = 4.0;  // correspondences within this many stage voxels
};

struct IcpResult {
  Eigen::Matrix4d transform = Eigen::Matrix4d::Identity();
  double rmse_m = 0.0;   // RMS point-to-plane residual of the final inliers
  double overlap = 0.0;  // share of source points with a target point within the final distance
  std::size_t inliers = 0;
  bool converged = false;
  int iterations = 0;
};

// source/target: point sets at spacing voxel_m (coarser stages are voxelised from them).
IcpResult refine_icp(const std::vector<Eigen::Vector3f>& source, const std::vector<Eigen::Vector3f>& target,
                     const Eigen::Matrix4d& initial, const IcpParams& params, const CancellationToken* cancel = nullptr);

// Normals by local PCA with neighbours within radius_m; zero where fewer than 3 neighbours.
std::vector<Eigen::Vector3f> estimate_normals(const std::vector<Eigen::Vector3f>& points, double radius_m);

}  // namespace k4reg
