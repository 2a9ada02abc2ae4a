#include "api/proto_convert.h"

#include <openssl/evp.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <memory>
#include <string>

#include "enum_convert.h"
#include "k4reg/util/error.h"
#include "messages_to_core.h"

namespace k4reg::service {
namespace {

// The core owns the valid ranges; checking them here refuses bad parameters before a job is queued or
// an upload accepted.
void check_ranges(const RegistrationParams& params) {
  try {
    validate(params);
  } catch (const Error& e) {
    fail(e.code(), std::string("params.") + e.what());
  }
}

}  // namespace

RegistrationParams params_from_proto(const v1::RegistrationParams& m) {
  RegistrationParams p;
  if (m.has_min_scale_m()) p.min_scale_m = m.min_scale_m();
  if (m.has_overlap()) p.overlap = m.overlap();
  if (m.has_octaves()) p.octaves = m.octaves();
  if (m.has_scales_per_octave()) p.scales_per_octave = m.scales_per_octave();
  if (m.has_min_contrast()) p.min_contrast = m.min_contrast();
  p.signal = api::from_proto(m.signal());
  p.method = api::from_proto(m.method());
  if (m.has_plain_voxel_m()) p.plain_voxel_m = m.plain_voxel_m();
  if (m.has_max_bases()) p.max_bases = m.max_bases();
  if (m.has_hypotheses_kept()) p.hypotheses_kept = m.hypotheses_kept();
  if (m.has_icp()) p.icp = m.icp();
  if (m.has_levelled()) p.levelled = m.levelled();
  if (m.has_search_other_side()) p.search_other_side = m.search_other_side();
  if (m.has_icp_max_iterations()) p.icp_max_iterations = m.icp_max_iterations();
  if (m.has_seed()) p.seed = m.seed();
  if (m.has_threads()) p.threads = m.threads();
  if (m.has_time_budget_s()) p.time_budget_s = m.time_budget_s();
  p.free_space = api::from_proto(m.free_space());
  check_ranges(p);
  return p;
}

void matrix_to_proto(const Eigen::Matrix4d& matrix, google::protobuf::RepeatedField<double>* values) {
  values->Clear();
  values->Reserve(16);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) values->Add(matrix(r, c));
}

void points_to_proto(const std::vector<Eigen::Vector3d>& points, google::protobuf::RepeatedField<double>* values) {
  values->Clear();
  for (const Eigen::Vector3d& p : points) values->Add(p.data(), p.data() + 3);
}

std::size_t preview_points_from_proto(std::uint32_t points) {
  if (points > kMaxPreviewPoints)
    fail(ErrorCode::kInvalidArgument,
         "preview_points must be at most " + std::to_string(kMaxPreviewPoints) + " (0 = no preview)");
  return points;
}

void preview_to_proto(const CloudPreview& preview, v1::Preview* m) {
  m->clear_offset_m();
  m->mutable_offset_m()->Add(preview.offset_m.data(), preview.offset_m.data() + 3);
  m->set_distance_cap_m(preview.distance_cap_m);
  m->clear_clouds();
  static_assert(std::endian::native == std::endian::little, "the API's previews are little-endian float32");
  auto bytes = [](const auto& values) {
    return std::string(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(values[0]));
  };
  for (const PreviewCloud& cloud : preview.clouds) {
    v1::PreviewCloud* out = m->add_clouds();
    out->set_name(cloud.name);
    out->set_points(cloud.points);
    out->set_xyz(bytes(cloud.xyz));
    out->set_distance_m(bytes(cloud.distance_m));
    out->set_keypoints_xyz(bytes(cloud.keypoints));
  }
}

void scanner_to_proto(const ScannerPosition& scanner, v1::ScannerPosition* m) {
  m->clear_point_m();
  if (scanner.source != ScannerSource::kNone)
    for (int axis = 0; axis < 3; ++axis) m->add_point_m(scanner.position_m(axis));
  m->set_source(to_string(scanner.source));
  m->set_fit(scanner.fit.share);
  m->set_angular_step_rad(scanner.fit.step_rad);
  m->set_reason(scanner.reason);
}

void result_to_proto(const RegistrationResult& r, v1::RegistrationResult* m) {
  matrix_to_proto(r.transform, m->mutable_transform());
  m->set_rmse_m(r.rmse_m);
  m->set_overlap(r.overlap);
  m->set_inliers(r.inliers);
  m->set_source_points(r.source_points);
  m->set_target_points(r.target_points);
  m->set_source_voxels(r.source_voxels);
  m->set_target_voxels(r.target_voxels);
  m->set_source_keypoints(r.source_keypoints);
  m->set_target_keypoints(r.target_keypoints);
  m->set_signal(r.signal);
  m->set_ambiguity_margin(r.ambiguity_margin);
  m->set_ambiguous(r.ambiguous);
  m->set_ambiguity_reason(r.ambiguity_reason);
  m->set_well_supported(r.well_supported);
  m->set_free_space_used(r.free_space_used);
  scanner_to_proto(r.source_scanner, m->mutable_source_scanner_position());
  scanner_to_proto(r.target_scanner, m->mutable_target_scanner_position());
  m->set_min_scale_m_used(r.min_scale_m_used);
  m->set_overlap_used(r.overlap_used);
  m->clear_hypotheses();
  for (const Hypothesis& h : r.hypotheses) {
    v1::Hypothesis* out = m->add_hypotheses();
    matrix_to_proto(h.transform, out->mutable_transform());
    out->set_keypoint_score(h.keypoint_score);
    out->set_cloud_score(h.cloud_score);
    out->set_refined_score(h.refined_score);
    out->set_surface_agreement(h.surface_agreement);
    points_to_proto(h.base_source_m, out->mutable_base_source_m());
    points_to_proto(h.base_target_m, out->mutable_base_target_m());
  }
  m->set_bases_tried(r.bases_tried);
  m->set_seed(r.seed);
  m->set_icp_converged(r.icp_converged);
  m->set_icp_iterations(r.icp_iterations);
  constraint_to_proto(r.constraint, m);
  m->clear_timings();
  for (const StageTiming& t : r.timings) {
    v1::StageTiming* out = m->add_timings();
    out->set_stage(t.stage);
    out->set_seconds(t.seconds);
  }
}

void params_to_proto(const RegistrationParams& p, v1::RegistrationParams* m) {
  m->set_min_scale_m(p.min_scale_m);
  m->set_overlap(p.overlap);
  m->set_octaves(p.octaves);
  m->set_scales_per_octave(p.scales_per_octave);
  m->set_min_contrast(p.min_contrast);
  m->set_signal(api::to_proto(p.signal));
  m->set_method(api::to_proto(p.method));
  m->set_plain_voxel_m(p.plain_voxel_m);
  m->set_max_bases(p.max_bases);
  m->set_hypotheses_kept(p.hypotheses_kept);
  m->set_icp(p.icp);
  m->set_levelled(p.levelled);
  m->set_search_other_side(p.search_other_side);
  m->set_icp_max_iterations(p.icp_max_iterations);
  m->set_seed(p.seed);
  m->set_threads(p.threads);
  m->set_time_budget_s(p.time_budget_s);
  m->set_free_space(api::to_proto(p.free_space));
}

namespace {

template <typename T>
std::string bytes_of(const std::vector<T>& values) {
  return std::string(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}

}  // namespace

void cloud_to_proto(const PointCloud& cloud, const std::string& name, v1::PairCloud* m) {
  m->set_name(name);
  m->set_points_xyz(bytes_of(cloud.points));
  m->set_intensity(bytes_of(cloud.intensity));
  m->clear_origin_m();
  m->mutable_origin_m()->Add(cloud.origin_m.data(), cloud.origin_m.data() + 3);
}

PointCloud cloud_from_proto(const v1::PairCloud& m, std::size_t max_points) {
  const std::string name = m.name().empty() ? "pair cloud" : m.name();
  PointCloud cloud;
  cloud.points = api::vectors_from_bytes(m.points_xyz(), name + " points_xyz");
  cloud.intensity = api::floats_from_bytes(m.intensity(), name + " intensity");
  if (!cloud.intensity.empty() && cloud.intensity.size() != cloud.points.size())
    fail(ErrorCode::kInvalidArgument, name + ": intensity must be empty or one value per point");
  if (max_points > 0 && cloud.points.size() > max_points)
    fail(ErrorCode::kResourceExhausted, name + ": " + std::to_string(cloud.points.size()) + " points, more than " +
                                            std::to_string(max_points) + " (--max-points)");
  if (m.origin_m_size() != 3) fail(ErrorCode::kInvalidArgument, name + ": origin_m must have 3 values");
  cloud.origin_m = Eigen::Vector3d(m.origin_m(0), m.origin_m(1), m.origin_m(2));
  if (!cloud.origin_m.allFinite()) fail(ErrorCode::kInvalidArgument, name + ": origin_m is not finite");
  for (const Eigen::Vector3f& p : cloud.points)
    if (!p.allFinite()) fail(ErrorCode::kInvalidArgument, name + ": a point is NaN or infinite");
  for (const float value : cloud.intensity)
    if (!std::isfinite(value)) fail(ErrorCode::kInvalidArgument, name + ": an intensity is NaN or infinite");
  return cloud;
}

std::string cloud_digest(const v1::PairCloud& m) {
  static_assert(std::endian::native == std::endian::little, "the digest covers little-endian float64 origins");
  const std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> context(EVP_MD_CTX_new(), EVP_MD_CTX_free);
  std::string digest(EVP_MAX_MD_SIZE, '\0');
  unsigned int length = 0;
  bool ok = context && EVP_DigestInit_ex(context.get(), EVP_sha256(), nullptr) == 1 &&
            EVP_DigestUpdate(context.get(), m.points_xyz().data(), m.points_xyz().size()) == 1 &&
            EVP_DigestUpdate(context.get(), m.intensity().data(), m.intensity().size()) == 1;
  for (const double coordinate : m.origin_m())
    ok = ok && EVP_DigestUpdate(context.get(), &coordinate, sizeof coordinate) == 1;
  if (!ok || EVP_DigestFinal_ex(context.get(), reinterpret_cast<unsigned char*>(digest.data()), &length) != 1)
    fail(ErrorCode::kInternal, "SHA-256 failed");
  digest.resize(length);
  return digest;
}

}  // namespace k4reg::service
