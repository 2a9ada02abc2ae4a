#include "k4reg/qa/cloud_preview.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "k4reg/geometry/neighbor_grid.h"
#include "k4reg/geometry/sampling.h"
#include "k4reg/util/error.h"

namespace k4reg {
namespace {

// The cap when none is given: three minimum scales, well past what a true pose leaves between two scans.
constexpr double kCapPerScale = 3.0;

void validate(const PreviewParams& params) {
  if (params.max_points == 0 || params.max_points > kMaxPreviewPoints)
    fail(ErrorCode::kInvalidArgument, "preview points must be in [1, " + std::to_string(kMaxPreviewPoints) + "]");
  if (!(params.distance_cap_m >= 0.0 && params.distance_cap_m <= 1e6))
    fail(ErrorCode::kInvalidArgument, "preview distance cap must be in [0, 1e6] m");
}

// The cloud's points in the common frame, minus the offset: pose * (origin + p) - offset.
std::vector<Eigen::Vector3f> in_frame(const PointCloud& cloud, const Eigen::Matrix4d& pose, const Eigen::Vector3d& offset) {
  const Eigen::Matrix3d rotation = pose.topLeftCorner<3, 3>();
  const Eigen::Matrix3f r = rotation.cast<float>();
  const Eigen::Vector3f shift = (rotation * cloud.origin_m + pose.topRightCorner<3, 1>() - offset).cast<float>();
  std::vector<Eigen::Vector3f> out(cloud.size());
  tbb::parallel_for(std::size_t{0}, out.size(), [&](std::size_t i) { out[i] = r * cloud.points[i] + shift; });
  return out;
}

// Shares of the budget: even, with what small clouds leave over going to the larger ones.
std::vector<std::size_t> shares(const std::vector<std::size_t>& sizes, std::size_t budget) {
  std::vector<std::size_t> share(sizes.size(), 0);
  std::vector<std::size_t> open;
  for (std::size_t i = 0; i < sizes.size(); ++i)
    if (sizes[i] > 0) open.push_back(i);
  while (!open.empty() && budget > 0) {
    const std::size_t each = std::max<std::size_t>(1, budget / open.size());
    std::vector<std::size_t> still_open;
    for (std::size_t i : open) {
      const std::size_t take = std::min({each, sizes[i] - share[i], budget});
      share[i] += take;
      budget -= take;
      if (share[i] < sizes[i]) still_open.push_back(i);
    }
    open = std::move(still_open);
  }
  return share;
}

// `count` of the indices [0, n), in increasing order, drawn at random with the seed.
std::vector<std::size_t> subsample(std::size_t n, std::size_t count, std::uint64_t seed) {
  std::vector<std::size_t> all(n);
  std::iota(all.begin(), all.end(), 0);
  if (count >= n) return all;
  std::vector<std::size_t> kept;
  kept.reserve(count);
  std::mt19937_64 rng(seed);
  std::sample(all.begin(), all.end(), std::back_inserter(kept), count, rng);
  return kept;
}

// The shared part of both previews: clouds[i] placed by poses[i] (none: listed without points).
CloudPreview build(const std::vector<const PointCloud*>& clouds, const std::vector<std::optional<Eigen::Matrix4d>>& poses,
                   const std::vector<std::string>& names, const Eigen::Vector3d& offset, double cap_m,
                   const PreviewParams& params, const CancellationToken* cancel) {
  CloudPreview preview;
  preview.offset_m = offset;
  preview.distance_cap_m = cap_m;
  const std::size_t n = clouds.size();
  std::vector<std::vector<Eigen::Vector3f>> moved(n);
  std::vector<std::optional<NeighborGrid>> grids(n);
  std::vector<std::size_t> sizes(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    check(cancel);
    if (!poses[i] || clouds[i]->empty()) continue;
    moved[i] = in_frame(*clouds[i], *poses[i], offset);
    grids[i].emplace(moved[i], cap_m);
    sizes[i] = moved[i].size();
  }
  const std::vector<std::size_t> share = shares(sizes, params.max_points);
  const float cap = static_cast<float>(cap_m);
  for (std::size_t i = 0; i < n; ++i) {
    PreviewCloud& out = preview.clouds.emplace_back();
    out.name = names[i];
    out.points = clouds[i]->size();
    if (share[i] == 0) continue;
    const std::vector<std::size_t> kept = subsample(sizes[i], share[i], params.seed + i);
    out.xyz.resize(kept.size());
    out.distance_m.resize(kept.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, kept.size(), 4096), [&](const tbb::blocked_range<std::size_t>& range) {
      check(cancel);
      for (std::size_t k = range.begin(); k < range.end(); ++k) {
        const Eigen::Vector3f& q = moved[i][kept[k]];
        float nearest = cap;
        for (std::size_t j = 0; j < n; ++j) {
          float d2 = 0.0f;
          if (j != i && grids[j] && grids[j]->nearest_within(q, cap, &d2) >= 0) nearest = std::min(nearest, std::sqrt(d2));
        }
        out.xyz[k] = q;
        out.distance_m[k] = nearest;
      }
    });
  }
  check(cancel);
  return preview;
}

}  // namespace

CloudPreview make_pair_preview(const PointCloud& source, const PointCloud& target, const RegistrationResult& result,
                               const PreviewParams& params, const CancellationToken* cancel) {
  validate(params);
  const double cap = params.distance_cap_m > 0 ? params.distance_cap_m : kCapPerScale * result.min_scale_m_used;
  if (!(cap > 0)) fail(ErrorCode::kInvalidArgument, "preview: the result has no minimum scale; give a distance cap");
  const Eigen::Matrix4d identity = Eigen::Matrix4d::Identity();
  CloudPreview preview =
      build({&source, &target}, {result.transform, identity}, {"source", "target"}, target.origin_m, cap, params, cancel);
  const Eigen::Matrix3d r = result.transform.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = result.transform.topRightCorner<3, 1>();
  for (const Eigen::Vector3d& p : result.source_keypoint_positions_m)
    preview.clouds[0].keypoints.push_back((r * p + t - target.origin_m).cast<float>());
  for (const Eigen::Vector3d& p : result.target_keypoint_positions_m)
    preview.clouds[1].keypoints.push_back((p - target.origin_m).cast<float>());
  return preview;
}

CloudPreview make_project_preview(const std::vector<PointCloud>& scans, const std::vector<std::string>& names,
                                  const ProjectResult& result, const PreviewParams& params,
                                  const CancellationToken* cancel) {
  validate(params);
  if (scans.size() != result.scans.size() || names.size() != scans.size() || result.reference >= scans.size())
    fail(ErrorCode::kInvalidArgument, "preview: the scans, their names and the project result do not match");
  double cap = params.distance_cap_m;
  if (cap <= 0) {
    for (const ProjectLink& link : result.links)
      if (link.accepted) cap = std::max(cap, kCapPerScale * link.min_scale_m_used);
    // No accepted link (the reference alone): ten point spacings of the reference.
    if (cap <= 0) cap = 10.0 * measure_sampling(scans[result.reference]).spacing_m;
    if (!(cap > 0)) fail(ErrorCode::kInvalidArgument, "preview: cannot choose a distance cap; give one");
  }
  std::vector<const PointCloud*> clouds;
  std::vector<std::optional<Eigen::Matrix4d>> poses;
  for (std::size_t i = 0; i < scans.size(); ++i) {
    clouds.push_back(&scans[i]);
    poses.push_back(result.scans[i].registered ? std::optional<Eigen::Matrix4d>(result.scans[i].pose) : std::nullopt);
  }
  return build(clouds, poses, names, scans[result.reference].origin_m, cap, params, cancel);
}

}  // namespace k4reg
