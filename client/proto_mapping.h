// Core structs <-> k4reg.v1 messages on the client side: the inverse of the server's proto_convert
// (parameters go out, results come back), kept here so the client links the generated stubs, not the
// service library.
#pragma once

#include "k4reg/qa/cloud_preview.h"
#include "k4reg/registration/registration.h"
#include "k4reg/v1/registration.pb.h"
#include "registration_flags.h"

namespace k4reg::cli {

// Only the parameters whose flags were given are set; the rest stay unset, so the server's defaults apply
// (the same values as the local defaults, except threads: the server's --job-threads, not all cores).
v1::RegistrationParams params_to_proto(const RegistrationParams& params, const RegistrationFlags& flags);

// Throws CommandError for a transform that is not 16 numbers (a server of another API version).
Eigen::Matrix4d matrix_from_proto(const google::protobuf::RepeatedField<double>& values);
RegistrationResult result_from_proto(const v1::RegistrationResult& message);
// x, y, z of each point in turn -> points. Throws CommandError for a count that is not a multiple of 3.
std::vector<Eigen::Vector3d> points_from_proto(const google::protobuf::RepeatedField<double>& values);
// Throws CommandError for byte arrays that are not whole float32 values, or not one distance per point.
CloudPreview preview_from_proto(const v1::Preview& message);

}  // namespace k4reg::cli
