#include "k4reg/registration/pose_score.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <utility>

namespace k4reg {
namespace {

constexpr std::size_t kScoredPoints = 30000;  // a share to within ~0.3 % (one standard deviation)
constexpr std::size_t kStage = 1;              // the symmetry guard's
constexpr float kNearVoxels = 2.0f;            // "near the surface": within this many finest voxels
constexpr float kOnVoxels = 0.5f;              // "on it": point-to-plane within this many

}  // namespace

PoseScorer::PoseScorer(const IcpPyramid& source, const IcpPyramid& target, const ScanViews* views, double overlap)
    : scored_(scored_source(source.stages.at(std::min(kStage, source.stages.size() - 1)), kScoredPoints)),
      finest_(every_kth(source.stages.back().points, kScoredPoints)),
      reference_(target.stages.at(std::min(kStage, target.stages.size() - 1))),
      finest_reference_(target.stages.back()),
      views_(views),
      overlap_(overlap),
      tau_(static_cast<float>(1.5 * reference_.voxel_m)) {}

double PoseScorer::score(const Eigen::Matrix4d& t) const {
  return cloud_score(scored_, reference_, *reference_.grid, tau_, t, views_, overlap_);
}

double surface_agreement(const std::vector<Eigen::Vector3f>& points, const Eigen::Matrix4d& t,
                         const IcpPyramid::Stage& reference) {
  const Eigen::Matrix3f r = t.topLeftCorner<3, 3>().cast<float>();
  const Eigen::Vector3f shift = t.topRightCorner<3, 1>().cast<float>();
  const auto voxel = static_cast<float>(reference.voxel_m);
  // Integer counts: the same for any split over threads.
  const auto [near, on] = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, points.size(), 4096), std::pair<std::size_t, std::size_t>{0, 0},
      [&](const tbb::blocked_range<std::size_t>& range, std::pair<std::size_t, std::size_t> c) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
          const Eigen::Vector3f q = r * points[i] + shift;
          const int k = reference.grid->nearest_within(q, kNearVoxels * voxel);
          if (k < 0 || reference.normals[k].isZero()) continue;
          ++c.first;
          if (std::abs(reference.normals[k].dot(q - reference.points[k])) < kOnVoxels * voxel) ++c.second;
        }
        return c;
      },
      [](std::pair<std::size_t, std::size_t> a, const std::pair<std::size_t, std::size_t>& b) {
        return std::pair<std::size_t, std::size_t>{a.first + b.first, a.second + b.second};
      });
  return near > 0 ? static_cast<double>(on) / static_cast<double>(near) : 0.0;
}

double PoseScorer::surface_agreement(const Eigen::Matrix4d& t) const {
  return k4reg::surface_agreement(finest_, t, finest_reference_);
}

}  // namespace k4reg
