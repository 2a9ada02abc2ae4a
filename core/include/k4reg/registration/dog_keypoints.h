// 3D difference-of-Gaussians keypoints (paper Sec. 2.1) on a voxelised cloud carrying a scalar signal.
// Octave o works on a voxel grid of spacing min_scale * 2^o, so each octave costs about a quarter of
// the previous one; within an octave the signal is smoothed at scales_per_octave + 3 Gaussian scales
// (normalised convolution over the surface voxels) and keypoints are extrema of the DoG over their
// 3-D neighbourhood and the adjacent scales.
// Beyond the paper, for repeatability between scans: a candidate must see the surface on all sides at
// its scale (no occlusion borders, window holes or scan edges, whose response depends on the viewpoint)
// and enough voxels around it (no sparse far-field voxels).
#pragma once

#include <vector>

#include "k4reg/util/cancellation.h"
#include "k4reg/geometry/point_cloud.h"

namespace k4reg {

struct DogParams {
  double min_scale_m = 0.05;
  int octaves = 5;
  int scales_per_octave = 5;
  double min_contrast = 0.01;        // fraction of the signal's (robust) range
  double min_coverage = 0.6;         // Gaussian weight present / expected on a fully sampled plane
  double max_border_offset = 0.35;   // |weighted neighbour centroid - point| / scale
};

struct DogKeypoints {
  std::vector<Eigen::Vector3f> points;
  std::vector<float> scale_m;
  std::vector<float> response;  // DoG value (signed)
};

// points: voxel centroids at spacing params.min_scale_m; signal: one value per point.
DogKeypoints detect_dog_keypoints(const std::vector<Eigen::Vector3f>& points, const std::vector<float>& signal,
                                  const DogParams& params, const CancellationToken* cancel = nullptr);

}  // namespace k4reg
