#include "pcl_methods.h"

#include <pcl/common/common.h>
#include <pcl/features/normal_3d_omp.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/keypoints/sift_keypoint.h>
#include <pcl/registration/ia_fpcs.h>
#include <pcl/registration/ia_kfpcs.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace k4reg::bench {

PclCloud::Ptr to_pcl(const PointCloud& cloud) {
  auto out = std::make_shared<PclCloud>();
  out->resize(cloud.size());
  const bool intensity = cloud.has_intensity();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    pcl::PointXYZI& p = (*out)[i];
    p.x = cloud.points[i].x();
    p.y = cloud.points[i].y();
    p.z = cloud.points[i].z();
    p.intensity = intensity ? cloud.intensity[i] : 0.0f;
  }
  return out;
}

std::int64_t pcl_voxel_grid_cells(const PclCloud& cloud, double leaf_m) {
  if (cloud.empty()) return 0;
  Eigen::Vector4f lo, hi;
  pcl::getMinMax3D(cloud, lo, hi);
  // The same arithmetic as pcl::VoxelGrid::applyFilter (filters/impl/voxel_grid.hpp, PCL 1.13).
  const float inverse = static_cast<float>(1.0 / leaf_m);
  std::int64_t cells = 1;
  for (int axis = 0; axis < 3; ++axis) cells *= static_cast<std::int64_t>((hi[axis] - lo[axis]) * inverse) + 1;
  return cells;
}

bool pcl_voxel_grid_overflows(const PclCloud& cloud, double leaf_m) {
  return pcl_voxel_grid_cells(cloud, leaf_m) > static_cast<std::int64_t>(std::numeric_limits<std::int32_t>::max());
}

PclCloud::Ptr pcl_voxel_grid(const PclCloud::ConstPtr& cloud, double leaf_m) {
  pcl::VoxelGrid<pcl::PointXYZI> grid;
  const float leaf = static_cast<float>(leaf_m);
  grid.setLeafSize(leaf, leaf, leaf);
  grid.setInputCloud(cloud);
  auto out = std::make_shared<PclCloud>();
  grid.filter(*out);
  return out;
}

namespace {

// Curvature (lambda_min / sum of lambdas of the local covariance) in the intensity field.
PclCloud::Ptr with_curvature_signal(const PclCloud::ConstPtr& cloud, double sigma_m) {
  PclCloud::Ptr voxels = pcl_voxel_grid(cloud, sigma_m);
  pcl::NormalEstimationOMP<pcl::PointXYZI, pcl::Normal> estimation(2);
  estimation.setInputCloud(voxels);
  estimation.setRadiusSearch(3.0 * sigma_m);
  pcl::PointCloud<pcl::Normal> normals;
  estimation.compute(normals);
  for (std::size_t i = 0; i < voxels->size(); ++i)
    (*voxels)[i].intensity = std::isfinite(normals[i].curvature) ? normals[i].curvature : 0.0f;
  return voxels;
}

float intensity_range(const PclCloud& cloud) {
  float lo = std::numeric_limits<float>::max(), hi = std::numeric_limits<float>::lowest();
  for (const auto& p : cloud) lo = std::min(lo, p.intensity), hi = std::max(hi, p.intensity);
  return cloud.empty() ? 0.0f : hi - lo;
}

template <typename Aligner>
Eigen::Matrix4d align(Aligner& aligner, const PclCloud::ConstPtr& source, const PclCloud::ConstPtr& target,
                     const PclAlignParams& params) {
  aligner.setInputSource(source);
  aligner.setInputTarget(target);
  aligner.setApproxOverlap(static_cast<float>(params.overlap));
  aligner.setDelta(static_cast<float>(params.delta_m), false);
  // The default threshold (1 - overlap) aborts on the first candidate scoring below it, which for
  // KFPCS's MSAC cost is often a 180-degree flip; 0 makes every method run all its iterations.
  aligner.setScoreThreshold(0.0f);
  aligner.setMaximumIterations(params.max_iterations);
  aligner.setMaxComputationTime(params.max_seconds);
  aligner.setNumberOfThreads(params.threads);
  PclCloud aligned;
  aligner.align(aligned);
  return aligner.getFinalTransformation().template cast<double>();
}

}  // namespace

int sift_overflowed_octaves(const PclCloud& cloud, const SiftParams& params) {
  // SIFTKeypoint voxelises every octave at its scale, starting at min_scale; a refused octave runs on the
  // previous octave's cloud, at worst the raw scan. Voxelising hardly changes the bounding box.
  int refused = 0;
  for (int octave = 0; octave < params.octaves; ++octave)
    refused += pcl_voxel_grid_overflows(cloud, params.min_scale_m * (1 << octave));
  return refused;
}

SiftKeypoints pcl_sift_keypoints(const PclCloud::ConstPtr& cloud, bool has_intensity, const SiftParams& params) {
  SiftKeypoints out;
  const PclCloud::ConstPtr input = has_intensity ? cloud : with_curvature_signal(cloud, params.min_scale_m);
  out.overflowed_octaves = sift_overflowed_octaves(*input, params);

  pcl::SIFTKeypoint<pcl::PointXYZI, pcl::PointWithScale> sift;
  sift.setInputCloud(input);
  sift.setScales(static_cast<float>(params.min_scale_m), params.octaves, params.scales_per_octave);
  // Mandatory: the constructor leaves it at -FLT_MAX and compute() then fails.
  sift.setMinimumContrast(static_cast<float>(params.min_contrast_fraction * intensity_range(*input)));
  pcl::PointCloud<pcl::PointWithScale> keypoints;
  sift.compute(keypoints);
  out.points = std::make_shared<PclCloud>();
  for (const auto& k : keypoints) {
    pcl::PointXYZI p;
    p.x = k.x, p.y = k.y, p.z = k.z, p.intensity = 0.0f;
    out.points->push_back(p);
  }
  return out;
}

Eigen::Matrix4d pcl_kfpcs(const PclCloud::ConstPtr& source, const PclCloud::ConstPtr& target,
                          const PclAlignParams& params) {
  pcl::registration::KFPCSInitialAlignment<pcl::PointXYZI, pcl::PointXYZI> kfpcs;
  return align(kfpcs, source, target, params);
}

Eigen::Matrix4d pcl_fpcs(const PclCloud::ConstPtr& source, const PclCloud::ConstPtr& target,
                         const PclAlignParams& params) {
  pcl::registration::FPCSInitialAlignment<pcl::PointXYZI, pcl::PointXYZI> fpcs;
  return align(fpcs, source, target, params);
}

std::vector<Eigen::Vector3f> to_points(const PclCloud& cloud) {
  std::vector<Eigen::Vector3f> points;
  points.reserve(cloud.size());
  for (const auto& p : cloud) points.emplace_back(p.x, p.y, p.z);
  return points;
}

}  // namespace k4reg::bench
