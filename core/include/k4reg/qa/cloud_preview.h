// A preview of registered clouds, for looking at a registration (the QA report, the server's page): a random
// subsample of every cloud in one frame, each point with its distance to the nearest point of the other clouds,
// so a heat map shows where they agree and a slice shows a doubled wall.
// Cost: the clouds are moved into the frame once (12 bytes per input point), a neighbour grid is built on each,
// then one look-up per kept point and other cloud: about a second for 1 M kept points among 2 x 0.7 M.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "k4reg/geometry/point_cloud.h"
#include "k4reg/project/project_registration.h"
#include "k4reg/registration/registration.h"
#include "k4reg/util/cancellation.h"

namespace k4reg {

// The most points a preview holds in all: 16 bytes each (32 MB), about 43 MB as base64 in JSON.
constexpr std::size_t kMaxPreviewPoints = 2000000;

struct PreviewParams {
  std::size_t max_points = 1000000;  // in all, shared evenly among the clouds; (0, kMaxPreviewPoints]
  // Distances are capped here: a point at the cap has no neighbour within it (outside the overlap).
  // 0 = three times the minimum scale the registration used.
  double distance_cap_m = 0.0;
  std::uint64_t seed = 1;  // of the subsample: the same inputs give the same preview
};

struct PreviewCloud {
  std::string name;                         // "source", "target" or the scan's label
  std::size_t points = 0;                   // of the whole cloud
  std::vector<Eigen::Vector3f> xyz;         // in the common frame, minus CloudPreview::offset_m
  std::vector<float> distance_m;            // one per kept point, at most distance_cap_m
  std::vector<Eigen::Vector3f> keypoints;   // pairs: the points 4PCS matched, in the same frame
};

struct CloudPreview {
  Eigen::Vector3d offset_m = Eigen::Vector3d::Zero();  // float coordinates stay precise around it
  double distance_cap_m = 0.0;
  std::vector<PreviewCloud> clouds;  // pair: source (registered), target; project: one per scan
};

// Source moved by the result's transform onto the target, in the target's frame; source keypoints moved too.
CloudPreview make_pair_preview(const PointCloud& source, const PointCloud& target, const RegistrationResult& result,
                               const PreviewParams& params, const CancellationToken* cancel = nullptr);

// Every registered scan in the project frame; a scan that is not registered is listed without points (its
// name and size only), and is no neighbour of the others.
CloudPreview make_project_preview(const std::vector<PointCloud>& scans, const std::vector<std::string>& names,
                                  const ProjectResult& result, const PreviewParams& params,
                                  const CancellationToken* cancel = nullptr);

}  // namespace k4reg
