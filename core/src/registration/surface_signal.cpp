#include "k4reg/registration/surface_signal.h"

#include <Eigen/Eigenvalues>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "k4reg/util/error.h"
#include "k4reg/geometry/neighbor_grid.h"

namespace k4reg {

std::vector<float> surface_variation(const std::vector<Eigen::Vector3f>& points, double radius_m,
                                     const CancellationToken* cancel) {
  const NeighborGrid grid(points, radius_m);
  std::vector<float> variation(points.size(), 0.0f);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 4096), [&](const auto& range) {
    check(cancel);
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
      int count = 0;
      grid.for_each_within(points[i], static_cast<float>(radius_m), [&](std::uint32_t k, float) {
        const Eigen::Vector3d q = (points[k] - points[i]).cast<double>();
        sum += q;
        outer += q * q.transpose();
        ++count;
      });
      if (count < 4) continue;  // isolated voxels carry no shape: leave them flat
      const Eigen::Vector3d mean = sum / count;
      const Eigen::Matrix3d cov = outer / count - mean * mean.transpose();
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
      solver.computeDirect(cov, Eigen::EigenvaluesOnly);
      const Eigen::Vector3d l = solver.eigenvalues().cwiseMax(0.0);
      const double total = l.sum();
      if (total > 0) variation[i] = static_cast<float>(l(0) / total);
    }
  });
  return variation;
}

std::string surface_signal_name(KeypointSignal requested, bool use_intensity) {
  const bool intensity = requested == KeypointSignal::kIntensity || (requested == KeypointSignal::kAuto && use_intensity);
  return intensity ? "intensity" : "geometric";
}

SurfaceSignal make_surface_signal(const PointCloud& voxels, double voxel_m, KeypointSignal requested, bool use_intensity,
                                  const CancellationToken* cancel) {
  if (surface_signal_name(requested, use_intensity) == "intensity") {
    if (!voxels.has_intensity()) fail(ErrorCode::kInvalidArgument, "intensity signal requested but a cloud has no intensity");
    // Intensity is reflectance times an incidence and range falloff that differ between stations. In
    // log space those smooth factors become additive and the DoG (a band-pass) cancels them.
    std::vector<float> values(voxels.intensity.size());
    const auto [lo, hi] = std::minmax_element(voxels.intensity.begin(), voxels.intensity.end());
    const float floor = std::max(1e-6f, 1e-3f * (*hi - *lo));
    for (std::size_t i = 0; i < values.size(); ++i) values[i] = std::log(std::max(voxels.intensity[i] - *lo, 0.0f) + floor);
    return {std::move(values), "intensity"};
  }
  // Three voxels: enough neighbours (~28 on a plane) for a stable PCA, small enough to stay local.
  return {surface_variation(voxels.points, 3.0 * voxel_m, cancel), "geometric"};
}

}  // namespace k4reg
