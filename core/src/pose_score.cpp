#include "k4reg/pose_score.h"

#include <algorithm>

namespace k4reg {
namespace {

constexpr std::size_t kScoredPoints = 100000;  // a score to within ~0.3 %
constexpr std::size_t kStage = 1;              // the symmetry guard's

}  // namespace

PoseScorer::PoseScorer(const IcpPyramid& source, const IcpPyramid& target, const ScanViews* views, double overlap)
    : reference_(target.stages.at(std::min(kStage, target.stages.size() - 1))),
      views_(views),
      overlap_(overlap),
      tau_(static_cast<float>(1.5 * reference_.voxel_m)) {
  const auto& points = source.stages.at(std::min(kStage, source.stages.size() - 1)).points;
  const std::size_t step = std::max<std::size_t>(1, (points.size() + kScoredPoints - 1) / kScoredPoints);
  for (std::size_t i = 0; i < points.size(); i += step) scored_.push_back(points[i]);
}

double PoseScorer::score(const Eigen::Matrix4d& t) const {
  return cloud_score(scored_, reference_, *reference_.grid, tau_, t, views_, overlap_);
}

}  // namespace k4reg
