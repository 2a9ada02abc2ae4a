#include "truth_error.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <vector>

namespace k4reg::bench {

TransformError file_frame_error(const PointCloud& source, const Eigen::Matrix4d& estimate,
                                const Eigen::Matrix4d& truth) {
  const std::size_t stride = std::max<std::size_t>(1, source.size() / 200000);
  std::vector<Eigen::Vector3f> sample;
  for (std::size_t i = 0; i < source.size(); i += stride) sample.push_back(source.points[i]);
  // transform_error takes the cloud's local (float) points: move its origin into both transforms.
  const Eigen::Matrix4d shift = Eigen::Affine3d(Eigen::Translation3d(source.origin_m)).matrix();
  return transform_error(sample, estimate * shift, truth * shift);
}

}  // namespace k4reg::bench
