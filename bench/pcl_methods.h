// PCL 1.13's own K-4PCS pipeline and 4PCS baseline, run the way a PCL user would run them: SIFTKeypoint
// (PCL's "3D DoG") feeding KFPCSInitialAlignment, and FPCSInitialAlignment on a coarse VoxelGrid.
// Everything works in the clouds' local (float) frames; callers convert the transforms to file frames.
// This translation unit is compiled with OpenMP: PCL's FPCS/KFPCS templates are only multi-threaded
// when the code instantiating them is.
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "k4reg/geometry/point_cloud.h"

namespace k4reg::bench {

using PclCloud = pcl::PointCloud<pcl::PointXYZI>;

// Copies a cloud's local-frame points (and intensity, or 0) into a PCL cloud.
PclCloud::Ptr to_pcl(const PointCloud& cloud);

// The number of cells pcl::VoxelGrid computes for this leaf before filtering (its own arithmetic).
std::int64_t pcl_voxel_grid_cells(const PclCloud& cloud, double leaf_m);

// True when pcl::VoxelGrid would refuse this leaf for these points (more than INT32_MAX cells): it then
// only warns and returns its input unfiltered.
bool pcl_voxel_grid_overflows(const PclCloud& cloud, double leaf_m);

// pcl::VoxelGrid centroids.
PclCloud::Ptr pcl_voxel_grid(const PclCloud::ConstPtr& cloud, double leaf_m);

struct SiftParams {
  double min_scale_m = 0.05;
  int octaves = 5;
  int scales_per_octave = 5;
  double min_contrast_fraction = 0.01;  // of the signal's range (PCL wants an absolute value)
};

struct SiftKeypoints {
  PclCloud::Ptr points;            // keypoint positions (intensity unused)
  int overflowed_octaves = 0;      // octaves whose VoxelGrid refused the grid and ran on the raw cloud
};

// How many of SIFT's octaves pcl::VoxelGrid will refuse for this cloud (known before running SIFT).
int sift_overflowed_octaves(const PclCloud& cloud, const SiftParams& params);

// pcl::SIFTKeypoint on the intensity field. A cloud without intensity gets PCL's geometric stand-in
// instead: NormalEstimationOMP curvature (radius 3 sigma, as our surface variation) on a sigma voxel grid,
// written into the intensity field (what SIFTKeypoint<PointNormal> would read).
SiftKeypoints pcl_sift_keypoints(const PclCloud::ConstPtr& cloud, bool has_intensity, const SiftParams& params);

struct PclAlignParams {
  double delta_m = 0.05;   // absolute (setDelta(delta, false))
  double overlap = 0.8;
  int max_iterations = 100;
  int max_seconds = 600;   // setMaxComputationTime: checked between iterations only
  int threads = 2;
};

// Both return the transform source local -> target local (the identity when PCL found no candidate).
Eigen::Matrix4d pcl_kfpcs(const PclCloud::ConstPtr& source, const PclCloud::ConstPtr& target,
                          const PclAlignParams& params);
Eigen::Matrix4d pcl_fpcs(const PclCloud::ConstPtr& source, const PclCloud::ConstPtr& target,
                         const PclAlignParams& params);

std::vector<Eigen::Vector3f> to_points(const PclCloud& cloud);

}  // namespace k4reg::bench
