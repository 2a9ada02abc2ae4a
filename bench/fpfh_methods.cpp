#include "fpfh_methods.h"

#include <pcl/features/fpfh_omp.h>
#include <pcl/features/normal_3d_omp.h>
#include <pcl/registration/ia_ransac.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iterator>

namespace k4reg::bench {

FpfhCloud pcl_fpfh(const PclCloud::ConstPtr& cloud, const FpfhParams& params) {
  const PclCloud::Ptr voxels = pcl_voxel_grid(cloud, params.voxel_m);
  pcl::NormalEstimationOMP<pcl::PointXYZI, pcl::Normal> normal_estimation(params.threads);
  normal_estimation.setInputCloud(voxels);
  normal_estimation.setRadiusSearch(params.normal_radius_voxels * params.voxel_m);
  auto all_normals = std::make_shared<pcl::PointCloud<pcl::Normal>>();
  normal_estimation.compute(*all_normals);

  const auto finite_normal = [](const pcl::Normal& n) {
    return std::isfinite(n.normal_x) && std::isfinite(n.normal_y) && std::isfinite(n.normal_z);
  };
  auto points = std::make_shared<PclCloud>();
  auto normals = std::make_shared<pcl::PointCloud<pcl::Normal>>();
  for (std::size_t i = 0; i < voxels->size(); ++i)
    if (finite_normal((*all_normals)[i])) points->push_back((*voxels)[i]), normals->push_back((*all_normals)[i]);

  pcl::FPFHEstimationOMP<pcl::PointXYZI, pcl::Normal, pcl::FPFHSignature33> fpfh(params.threads);
  fpfh.setInputCloud(points);
  fpfh.setInputNormals(normals);
  fpfh.setRadiusSearch(params.feature_radius_voxels * params.voxel_m);
  pcl::PointCloud<pcl::FPFHSignature33> all_features;
  fpfh.compute(all_features);

  FpfhCloud out{std::make_shared<PclCloud>(), std::make_shared<pcl::PointCloud<pcl::FPFHSignature33>>(),
                pcl_voxel_grid_overflows(*cloud, params.voxel_m)};
  for (std::size_t i = 0; i < points->size(); ++i) {
    const auto& h = all_features[i].histogram;
    if (std::all_of(std::begin(h), std::end(h), [](float v) { return std::isfinite(v); }))
      out.points->push_back((*points)[i]), out.features->push_back(all_features[i]);
  }
  return out;
}

Eigen::Matrix4d pcl_sac_ia(const FpfhCloud& source, const FpfhCloud& target, const SacIaParams& params) {
  pcl::SampleConsensusInitialAlignment<pcl::PointXYZI, pcl::PointXYZI, pcl::FPFHSignature33> sac_ia;
  sac_ia.setInputSource(source.points);
  sac_ia.setSourceFeatures(source.features);
  sac_ia.setInputTarget(target.points);
  sac_ia.setTargetFeatures(target.features);
  sac_ia.setMaximumIterations(params.iterations);
  sac_ia.setMinSampleDistance(static_cast<float>(params.min_sample_distance_voxels * params.voxel_m));
  const double match_m = params.max_correspondence_voxels * params.voxel_m;
  sac_ia.setMaxCorrespondenceDistance(match_m * match_m);
  std::srand(params.seed);
  PclCloud aligned;
  sac_ia.align(aligned);
  return sac_ia.getFinalTransformation().cast<double>();
}

}  // namespace k4reg::bench
