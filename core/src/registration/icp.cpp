#include "k4reg/registration/icp.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>

#include "k4reg/geometry/neighbor_grid.h"
#include "k4reg/geometry/rigid_fit.h"
#include "k4reg/geometry/rigid_motion.h"
#include "k4reg/geometry/voxel_grid.h"

namespace k4reg {
namespace {

struct Accumulation {
  Eigen::Matrix<double, 6, 6> hessian = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> gradient = Eigen::Matrix<double, 6, 1>::Zero();
  double squared_residuals = 0.0;
  std::size_t inliers = 0;
  Accumulation& operator+=(const Accumulation& o) {
    hessian += o.hessian;
    gradient += o.gradient;
    squared_residuals += o.squared_residuals;
    inliers += o.inliers;
    return *this;
  }
};

std::vector<Eigen::Vector3f> downsample(const std::vector<Eigen::Vector3f>& points, double voxel_m) {
  PointCloud cloud;
  cloud.points = points;
  return voxel_grid(cloud, voxel_m).cloud.points;
}

// The source's centre (centre_m) and where a transform puts it: ICP turns the source about that point. About
// the frame's origin instead, an origin metres from the scan would make every linearised rotation a large
// translation, and float rounding of the moved points a step noise far above the convergence bar.
struct Pivot {
  Eigen::Vector3d centre_m, moved_m;
  Pivot(const Eigen::Vector3d& centre, const Eigen::Matrix4d& t)
      : centre_m(centre), moved_m(t.topLeftCorner<3, 3>() * centre + t.topRightCorner<3, 1>()) {}
};

// One linearised point-to-plane step at transform t (fixed grain: deterministic sums).
Accumulation accumulate(const std::vector<Eigen::Vector3f>& source, const std::vector<Eigen::Vector3f>& target,
                        const std::vector<Eigen::Vector3f>& normals, const NeighborGrid& grid, const Eigen::Matrix4d& t,
                        const Pivot& pivot, float max_distance, double kernel_m) {
  const double k2 = kernel_m * kernel_m;
  const Eigen::Matrix3f rotation = t.topLeftCorner<3, 3>().cast<float>();
  const Eigen::Vector3f centre = pivot.centre_m.cast<float>(), moved = pivot.moved_m.cast<float>();
  return tbb::parallel_deterministic_reduce(
      tbb::blocked_range<std::size_t>(0, source.size(), 2048), Accumulation{},
      [&](const tbb::blocked_range<std::size_t>& range, Accumulation acc) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
          const Eigen::Vector3f arm = rotation * (source[i] - centre);  // from the moved centre
          const Eigen::Vector3f p = moved + arm;
          const int j = grid.nearest_within(p, max_distance);
          if (j < 0 || normals[j].isZero()) continue;
          const Eigen::Vector3d n = normals[j].cast<double>();
          const double r = n.dot(pivot.moved_m - target[j].cast<double>() + arm.cast<double>());
          const double w = 1.0 / ((1.0 + r * r / k2) * (1.0 + r * r / k2));  // Geman-McClure
          Eigen::Matrix<double, 6, 1> jac;
          jac << arm.cast<double>().cross(n), n;
          acc.hessian += w * jac * jac.transpose();
          acc.gradient += w * r * jac;
          acc.squared_residuals += r * r;
          ++acc.inliers;
        }
        return acc;
      },
      [](Accumulation a, const Accumulation& b) { return a += b; });
}

// The Gauss-Newton step [rotation; translation]; levelled: the rotation about x and y stays zero (the 4 x 4
// system of the other unknowns).
Eigen::Matrix<double, 6, 1> solve_step(const Accumulation& acc, bool levelled) {
  if (!levelled) return acc.hessian.ldlt().solve(-acc.gradient);
  const Eigen::Matrix4d hessian = acc.hessian.bottomRightCorner<4, 4>();
  Eigen::Matrix<double, 6, 1> delta = Eigen::Matrix<double, 6, 1>::Zero();
  delta.tail<4>() = hessian.ldlt().solve(-acc.gradient.tail<4>());
  return delta;
}

}  // namespace

std::vector<Eigen::Vector3f> estimate_normals(const std::vector<Eigen::Vector3f>& points, const NeighborGrid& grid,
                                              double radius_m) {
  return estimate_normals(points, points, grid, radius_m);
}

std::vector<Eigen::Vector3f> estimate_normals(const std::vector<Eigen::Vector3f>& queries,
                                              const std::vector<Eigen::Vector3f>& points, const NeighborGrid& grid,
                                              double radius_m) {
  std::vector<Eigen::Vector3f> normals(queries.size(), Eigen::Vector3f::Zero());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, queries.size(), 4096), [&](const auto& range) {
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
      int count = 0;
      grid.for_each_within(queries[i], static_cast<float>(radius_m), [&](std::uint32_t k, float) {
        const Eigen::Vector3d q = (points[k] - queries[i]).cast<double>();
        sum += q;
        outer += q * q.transpose();
        ++count;
      });
      if (count < 3) continue;
      const Eigen::Vector3d mean = sum / count;
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
      solver.computeDirect(outer / count - mean * mean.transpose());
      normals[i] = solver.eigenvectors().col(0).cast<float>();
    }
  });
  return normals;
}

IcpPyramid make_icp_pyramid(const std::vector<Eigen::Vector3f>& points, const IcpParams& params, PyramidRole role,
                            const CancellationToken* cancel) {
  IcpPyramid pyramid;
  pyramid.stages.resize(params.stages);  // final addresses first: a grid refers to its stage's points
  for (int stage = 0; stage < params.stages; ++stage) {
    check(cancel);
    IcpPyramid::Stage& s = pyramid.stages[stage];
    s.voxel_m = params.voxel_m * std::pow(2.0, params.stages - 1 - stage);
    s.points = stage == params.stages - 1 ? points : downsample(points, s.voxel_m);
  }
  if (role == PyramidRole::kTarget) add_target_search(pyramid, params, cancel);
  return pyramid;
}

std::vector<Eigen::Vector3f> every_kth(const std::vector<Eigen::Vector3f>& points, std::size_t max_points) {
  const std::size_t step = std::max<std::size_t>(1, (points.size() + max_points - 1) / max_points);
  std::vector<Eigen::Vector3f> out;
  out.reserve(points.size() / step + 1);
  for (std::size_t i = 0; i < points.size(); i += step) out.push_back(points[i]);
  return out;
}

IcpPyramid thin_pyramid(const IcpPyramid& pyramid, std::size_t max_points) {
  IcpPyramid thin;
  thin.stages.resize(pyramid.stages.size());
  for (std::size_t s = 0; s < pyramid.stages.size(); ++s) {
    thin.stages[s].voxel_m = pyramid.stages[s].voxel_m;
    thin.stages[s].points = every_kth(pyramid.stages[s].points, max_points);
  }
  return thin;
}

void add_target_search(IcpPyramid& pyramid, const IcpParams& params, const CancellationToken* cancel) {
  for (IcpPyramid::Stage& s : pyramid.stages) {
    check(cancel);
    // One grid serves the correspondences and the normals (both look about 2.5 voxels around).
    s.grid = std::make_unique<NeighborGrid>(s.points, params.max_distance_factor * s.voxel_m);
    s.normals = estimate_normals(s.points, *s.grid, 2.5 * s.voxel_m);
  }
}

IcpResult refine_icp(const IcpPyramid& source, const IcpPyramid& target, const Eigen::Matrix4d& initial,
                     const IcpParams& params, const CancellationToken* cancel) {
  IcpResult result;
  result.transform = initial;
  const std::size_t stages =
      std::min({static_cast<std::size_t>(std::max(params.stages, 1)), source.stages.size(), target.stages.size()});
  for (std::size_t stage = params.finest_stage_only ? stages - 1 : 0; stage < stages; ++stage) {
    const auto& src = source.stages[stage];
    const auto& tgt = target.stages[stage];
    const double voxel = tgt.voxel_m;
    const float max_distance = static_cast<float>(params.max_distance_factor * voxel);
    const Eigen::Vector3d centre = centroid(src.points);
    result.converged = false;
    for (int it = 0; it < params.max_iterations; ++it) {
      check(cancel);
      const Pivot pivot(centre, result.transform);
      const Accumulation acc =
          accumulate(src.points, tgt.points, tgt.normals, *tgt.grid, result.transform, pivot, max_distance, voxel);
      ++result.iterations;
      if (acc.inliers < 6) break;
      const Eigen::Matrix<double, 6, 1> delta = solve_step(acc, params.levelled);
      if (!delta.allFinite()) break;
      Eigen::Matrix4d step = Eigen::Matrix4d::Identity();
      const double angle = delta.head<3>().norm();
      if (angle > 0) step.topLeftCorner<3, 3>() = Eigen::AngleAxisd(angle, delta.head<3>() / angle).toRotationMatrix();
      step.topRightCorner<3, 1>() = pivot.moved_m + delta.tail<3>() - step.topLeftCorner<3, 3>() * pivot.moved_m;
      result.transform = step * result.transform;
      if (angle < 1e-2 * params.converged_step_voxels && delta.tail<3>().norm() < params.converged_step_voxels * voxel) {
        result.converged = true;
        break;
      }
    }
    if (stage + 1 == stages && params.measure_fit) {
      const Accumulation acc = accumulate(src.points, tgt.points, tgt.normals, *tgt.grid, result.transform,
                                          Pivot(centre, result.transform), max_distance, voxel);
      result.inliers = acc.inliers;
      result.translation_information = acc.hessian.bottomRightCorner<3, 3>();
      result.rmse_m = acc.inliers ? std::sqrt(acc.squared_residuals / acc.inliers) : 0.0;
      result.overlap = src.points.empty() ? 0.0 : double(acc.inliers) / src.points.size();
    }
  }
  return result;
}

}  // namespace k4reg
