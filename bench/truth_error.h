// Errors against the ground truth for transforms between two clouds' file frames (what register_clouds
// returns and what the simulator's and the data sets' ground truth give), shared by the benchmarks.
#pragma once

#include <Eigen/Core>

#include "k4reg/registration/metrics.h"
#include "k4reg/geometry/point_cloud.h"

namespace k4reg::bench {

// The paper's measures (k4reg::transform_error) of estimate against truth, both source -> target in the
// files' frames, on at most ~200 k evenly strided source points (plenty for a stable RMSE, cheap at 10 M).
TransformError file_frame_error(const PointCloud& source, const Eigen::Matrix4d& estimate,
                                const Eigen::Matrix4d& truth);

}  // namespace k4reg::bench
