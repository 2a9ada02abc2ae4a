#include "proto_mapping.h"

#include <fmt/format.h>

#include <bit>
#include <cstring>

#include "command_error.h"

namespace k4reg::cli {
namespace {

bool given(const CLI::Option* flag) { return flag->count() > 0; }

v1::KeypointSignal signal_to_proto(KeypointSignal signal) {
  switch (signal) {
    case KeypointSignal::kAuto: return v1::KEYPOINT_SIGNAL_AUTO;
    case KeypointSignal::kIntensity: return v1::KEYPOINT_SIGNAL_INTENSITY;
    case KeypointSignal::kGeometric: return v1::KEYPOINT_SIGNAL_GEOMETRIC;
  }
  return v1::KEYPOINT_SIGNAL_UNSPECIFIED;
}

v1::CoarseMethod method_to_proto(CoarseMethod method) {
  switch (method) {
    case CoarseMethod::kKeypoint4pcs: return v1::COARSE_METHOD_KEYPOINT_4PCS;
    case CoarseMethod::kPlain4pcs: return v1::COARSE_METHOD_PLAIN_4PCS;
  }
  return v1::COARSE_METHOD_UNSPECIFIED;
}

}  // namespace

v1::RegistrationParams params_to_proto(const RegistrationParams& p, const RegistrationFlags& flags) {
  v1::RegistrationParams m;
  if (given(flags.min_scale)) m.set_min_scale_m(p.min_scale_m);
  if (given(flags.overlap)) m.set_overlap(p.overlap);
  if (given(flags.no_icp)) m.set_icp(p.icp);
  if (given(flags.seed)) m.set_seed(p.seed);
  if (given(flags.threads)) m.set_threads(p.threads);
  if (given(flags.time_budget)) m.set_time_budget_s(p.time_budget_s);
  if (given(flags.bases)) m.set_max_bases(p.max_bases);
  if (given(flags.octaves)) m.set_octaves(p.octaves);
  if (given(flags.scales_per_octave)) m.set_scales_per_octave(p.scales_per_octave);
  if (given(flags.min_contrast)) m.set_min_contrast(p.min_contrast);
  if (given(flags.signal)) m.set_signal(signal_to_proto(p.signal));
  if (given(flags.method)) m.set_method(method_to_proto(p.method));
  if (given(flags.plain_voxel)) m.set_plain_voxel_m(p.plain_voxel_m);
  return m;
}

Eigen::Matrix4d matrix_from_proto(const google::protobuf::RepeatedField<double>& values) {
  if (values.size() != 16)
    throw CommandError("the server sent a transform of " + std::to_string(values.size()) + " numbers, not 16");
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = values.Get(4 * r + c);
  return m;
}

std::vector<Eigen::Vector3d> points_from_proto(const google::protobuf::RepeatedField<double>& values) {
  if (values.size() % 3 != 0)
    throw CommandError(fmt::format("the server sent {} point coordinates, not a multiple of 3", values.size()));
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < values.size(); i += 3) points.emplace_back(values[i], values[i + 1], values[i + 2]);
  return points;
}

namespace {

// Little-endian float32 values, `width` per item; a length that is not a whole number of items is a bad reply.
template <typename T>
std::vector<T> floats_from_bytes(const std::string& bytes, const char* what) {
  static_assert(std::endian::native == std::endian::little, "the API's previews are little-endian float32");
  if (bytes.size() % sizeof(T) != 0)
    throw CommandError(fmt::format("the server's preview has {} bytes of {}, not whole values", bytes.size(), what));
  std::vector<T> values(bytes.size() / sizeof(T));
  if (!values.empty()) std::memcpy(static_cast<void*>(values.data()), bytes.data(), bytes.size());
  return values;
}

}  // namespace

CloudPreview preview_from_proto(const v1::Preview& m) {
  CloudPreview preview;
  if (m.offset_m_size() == 3) preview.offset_m = Eigen::Vector3d(m.offset_m(0), m.offset_m(1), m.offset_m(2));
  preview.distance_cap_m = m.distance_cap_m();
  for (const v1::PreviewCloud& c : m.clouds()) {
    PreviewCloud& cloud = preview.clouds.emplace_back();
    cloud.name = c.name();
    cloud.points = c.points();
    cloud.xyz = floats_from_bytes<Eigen::Vector3f>(c.xyz(), "xyz");
    cloud.distance_m = floats_from_bytes<float>(c.distance_m(), "distance_m");
    cloud.keypoints = floats_from_bytes<Eigen::Vector3f>(c.keypoints_xyz(), "keypoints_xyz");
    if (cloud.distance_m.size() != cloud.xyz.size())
      throw CommandError("the server's preview of " + cloud.name + " has not one distance per point");
  }
  return preview;
}

RegistrationResult result_from_proto(const v1::RegistrationResult& m) {
  RegistrationResult r;
  r.transform = matrix_from_proto(m.transform());
  r.rmse_m = m.rmse_m();
  r.overlap = m.overlap();
  r.inliers = m.inliers();
  r.source_points = m.source_points();
  r.target_points = m.target_points();
  r.source_voxels = m.source_voxels();
  r.target_voxels = m.target_voxels();
  r.source_keypoints = m.source_keypoints();
  r.target_keypoints = m.target_keypoints();
  r.signal = m.signal();
  r.ambiguity_margin = m.ambiguity_margin();
  r.ambiguous = m.ambiguous();
  r.ambiguity_reason = m.ambiguity_reason();
  r.min_scale_m_used = m.min_scale_m_used();
  r.overlap_used = m.overlap_used();
  for (const v1::Hypothesis& h : m.hypotheses())
    r.hypotheses.push_back({matrix_from_proto(h.transform()), h.keypoint_score(), h.cloud_score(), h.refined_score(),
                            h.surface_agreement(), points_from_proto(h.base_source_m()),
                            points_from_proto(h.base_target_m())});
  r.bases_tried = m.bases_tried();
  r.seed = m.seed();
  r.icp_converged = m.icp_converged();
  r.icp_iterations = m.icp_iterations();
  for (const v1::StageTiming& t : m.timings()) r.timings.push_back({t.stage(), t.seconds()});
  return r;
}

}  // namespace k4reg::cli
