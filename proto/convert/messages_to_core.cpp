#include "messages_to_core.h"

#include <fmt/format.h>

#include <bit>
#include <cstring>

#include "k4reg/util/error.h"

namespace k4reg::api {
namespace {

template <typename T>
std::vector<T> values_from_bytes(const std::string& bytes, const std::string& what) {
  static_assert(std::endian::native == std::endian::little, "the API's byte fields are little-endian float32");
  if (bytes.size() % sizeof(T) != 0)
    fail(ErrorCode::kInvalidArgument, fmt::format("{}: {} bytes, not whole values", what, bytes.size()));
  std::vector<T> values(bytes.size() / sizeof(T));
  if (!values.empty()) std::memcpy(static_cast<void*>(values.data()), bytes.data(), bytes.size());
  return values;
}

}  // namespace

std::vector<float> floats_from_bytes(const std::string& bytes, const std::string& what) {
  return values_from_bytes<float>(bytes, what);
}

std::vector<Eigen::Vector3f> vectors_from_bytes(const std::string& bytes, const std::string& what) {
  return values_from_bytes<Eigen::Vector3f>(bytes, what);
}

namespace {

// An N x N matrix from its N * N numbers, row-major; `what` names it in the error.
template <int N>
Eigen::Matrix<double, N, N> square_from_proto(const google::protobuf::RepeatedField<double>& values, const char* what) {
  if (values.size() != N * N)
    fail(ErrorCode::kInvalidArgument, fmt::format("{} of {} numbers, not {}", what, values.size(), N * N));
  Eigen::Matrix<double, N, N> m;
  for (int r = 0; r < N; ++r)
    for (int c = 0; c < N; ++c) m(r, c) = values.Get(N * r + c);
  return m;
}

}  // namespace

Eigen::Matrix4d matrix_from_proto(const google::protobuf::RepeatedField<double>& values) {
  return square_from_proto<4>(values, "a transform");
}

Eigen::Matrix3d constraint_from_proto(const google::protobuf::RepeatedField<double>& values) {
  return values.empty() ? Eigen::Matrix3d::Zero() : square_from_proto<3>(values, "a translation constraint");
}

std::vector<Eigen::Vector3d> points_from_proto(const google::protobuf::RepeatedField<double>& values) {
  if (values.size() % 3 != 0)
    fail(ErrorCode::kInvalidArgument, fmt::format("{} point coordinates, not a multiple of 3", values.size()));
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < values.size(); i += 3) points.emplace_back(values[i], values[i + 1], values[i + 2]);
  return points;
}

ScannerPosition scanner_from_proto(const v1::ScannerPosition& m) {
  ScannerPosition s;
  s.source = scanner_source_named(m.source());
  if (m.point_m_size() == 3) s.position_m = Eigen::Vector3d(m.point_m(0), m.point_m(1), m.point_m(2));
  s.fit = {m.fit(), m.angular_step_rad()};
  s.reason = m.reason();
  return s;
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
  r.well_supported = m.well_supported();
  r.free_space_used = m.free_space_used();
  r.source_scanner = scanner_from_proto(m.source_scanner_position());
  r.target_scanner = scanner_from_proto(m.target_scanner_position());
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
  r.constraint = constraint_from_proto(m.constraint());
  for (const v1::StageTiming& t : m.timings()) r.timings.push_back({t.stage(), t.seconds()});
  return r;
}

CloudPreview preview_from_proto(const v1::Preview& m) {
  CloudPreview preview;
  if (m.offset_m_size() == 3) preview.offset_m = Eigen::Vector3d(m.offset_m(0), m.offset_m(1), m.offset_m(2));
  preview.distance_cap_m = m.distance_cap_m();
  for (const v1::PreviewCloud& c : m.clouds()) {
    PreviewCloud& cloud = preview.clouds.emplace_back();
    cloud.name = c.name();
    cloud.points = c.points();
    cloud.xyz = vectors_from_bytes(c.xyz(), "preview of " + cloud.name + ": xyz");
    cloud.distance_m = floats_from_bytes(c.distance_m(), "preview of " + cloud.name + ": distance_m");
    cloud.keypoints = vectors_from_bytes(c.keypoints_xyz(), "preview of " + cloud.name + ": keypoints_xyz");
    if (cloud.distance_m.size() != cloud.xyz.size())
      fail(ErrorCode::kInvalidArgument, "the preview of " + cloud.name + " has not one distance per point");
  }
  return preview;
}

}  // namespace k4reg::api
