// PCL 1.13's feature-based global registration, the peer of K-4PCS that PCL's tutorials teach (template
// alignment): FPFH descriptors on a voxel grid, matched by SampleConsensusInitialAlignment (SAC-IA). Works in
// the clouds' local (float) frames like pcl_methods.h; compiled with OpenMP for the *OMP estimators.
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Core>

#include "pcl_methods.h"

namespace k4reg::bench {

// Radii in voxels, as the tutorials scale them (Open3D's global registration uses the same two).
struct FpfhParams {
  double voxel_m = 0.05;
  double normal_radius_voxels = 2.0;
  double feature_radius_voxels = 5.0;
  int threads = 2;
};

struct FpfhCloud {
  PclCloud::Ptr points;                                 // voxel centroids with a usable normal and descriptor
  pcl::PointCloud<pcl::FPFHSignature33>::Ptr features;  // parallel to points
  bool voxel_grid_overflow = false;                     // pcl::VoxelGrid refused the grid: the raw cloud was described
};

// pcl::VoxelGrid, NormalEstimationOMP, FPFHEstimationOMP. Points whose normal or descriptor is not finite
// (too few neighbours) are dropped: SAC-IA's feature k-d tree would otherwise match NaNs.
FpfhCloud pcl_fpfh(const PclCloud::ConstPtr& cloud, const FpfhParams& params);

// PCL's template-alignment tutorial, distances in voxels (its voxel is 5 mm): 500 iterations, samples at least
// 10 voxels apart, a match counts within 2 voxels (SAC-IA's truncated error compares squared distances, so it
// gets the square).
struct SacIaParams {
  double voxel_m = 0.05;
  int iterations = 500;  // SAC-IA has no time limit: each iteration looks up every source point once
  double min_sample_distance_voxels = 10.0;
  double max_correspondence_voxels = 2.0;
  unsigned seed = 1;  // SAC-IA draws with rand(): seeded, so trials repeat (unlike PCL's FPCS)
};

// The transform source local -> target local (the identity when SAC-IA found none).
Eigen::Matrix4d pcl_sac_ia(const FpfhCloud& source, const FpfhCloud& target, const SacIaParams& params);

}  // namespace k4reg::bench
