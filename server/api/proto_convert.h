// k4reg.v1 messages <-> core structs. Shared by the gRPC service and the HTTP/JSON API.
#pragma once

#include "k4reg/qa/cloud_preview.h"
#include "k4reg/registration/registration.h"
#include "k4reg/registration/translation_constraint.h"
#include "k4reg/v1/registration.pb.h"

namespace k4reg::service {

// Unset fields take the core's defaults (the paper's values). Throws k4reg::Error(kInvalidArgument)
// naming the field for out-of-range values and unknown enum values.
RegistrationParams params_from_proto(const v1::RegistrationParams& message);

void result_to_proto(const RegistrationResult& result, v1::RegistrationResult* message);

// Points -> x, y, z of each in turn.
void points_to_proto(const std::vector<Eigen::Vector3d>& points, google::protobuf::RepeatedField<double>* values);

// A request's preview_points; throws k4reg::Error(kInvalidArgument) over kMaxPreviewPoints.
std::size_t preview_points_from_proto(std::uint32_t points);
void preview_to_proto(const CloudPreview& preview, v1::Preview* message);

// Every field set (the peer's defaults must not apply): the parameters a pair job is sent with.
void params_to_proto(const RegistrationParams& params, v1::RegistrationParams* message);

// A cloud as the core holds it, for RegisterPair; the inverse refuses malformed or non-finite clouds
// (kInvalidArgument) and clouds over max_points (kResourceExhausted; 0 = unlimited).
void cloud_to_proto(const PointCloud& cloud, const std::string& name, v1::PairCloud* message);
PointCloud cloud_from_proto(const v1::PairCloud& message, std::size_t max_points);
// SHA-256 of the cloud's points_xyz, intensity and origin_m (float64 little-endian): what PairCloud.digest holds.
std::string cloud_digest(const v1::PairCloud& message);

// Row-major 4x4 -> 16 repeated doubles.
void matrix_to_proto(const Eigen::Matrix4d& matrix, google::protobuf::RepeatedField<double>* values);
void scanner_to_proto(const ScannerPosition& scanner, v1::ScannerPosition* m);
// A translation constraint (translation_constraint.h) into a message's constraint (9 numbers, row-major),
// axis_constraint and weakest_constraint.
template <typename Message>
void constraint_to_proto(const Eigen::Matrix3d& constraint, Message* m) {
  m->clear_constraint();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m->add_constraint(constraint(r, c));
  m->clear_axis_constraint();
  for (const double axis : axis_constraint(constraint)) m->add_axis_constraint(axis);
  m->set_weakest_constraint(weakest_constraint(constraint));
}

}  // namespace k4reg::service
