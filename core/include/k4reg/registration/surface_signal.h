// The scalar signal the DoG detector runs on. Intensity when the scans have it (the paper); otherwise a
// geometric signal so clouds without intensity still work: the surface variation
// lambda_min / (lambda_0 + lambda_1 + lambda_2) of the local PCA, which is ~0 on planes and rises on
// edges, corners and curved parts. Cost: one neighbourhood per voxel (O(n) on voxelised clouds).
#pragma once

#include <string>
#include <vector>

#include "k4reg/util/cancellation.h"
#include "k4reg/geometry/point_cloud.h"
#include "k4reg/registration/registration_params.h"

namespace k4reg {

struct SurfaceSignal {
  std::vector<float> values;  // one per point
  std::string name;           // "intensity" or "geometric"
};

// Surface variation with neighbours within radius_m.
std::vector<float> surface_variation(const std::vector<Eigen::Vector3f>& points, double radius_m,
                                     const CancellationToken* cancel = nullptr);

// The name of the signal make_surface_signal picks: "intensity" or "geometric".
std::string surface_signal_name(KeypointSignal requested, bool use_intensity);

// Picks the signal for a voxelised cloud: `requested` kAuto means intensity when use_intensity is true.
// Throws kInvalidArgument when intensity is requested but the cloud has none.
SurfaceSignal make_surface_signal(const PointCloud& voxels, double voxel_m, KeypointSignal requested, bool use_intensity,
                                  const CancellationToken* cancel = nullptr);

}  // namespace k4reg
