// k4reg.v1 messages <-> core structs. Shared by the gRPC service and the HTTP/JSON API.
#pragma once

#include "k4reg/registration/registration.h"
#include "k4reg/v1/registration.pb.h"

namespace k4reg::service {

// Unset fields take the core's defaults (the paper's values). Throws k4reg::Error(kInvalidArgument)
// naming the field for out-of-range values and unknown enum values.
RegistrationParams params_from_proto(const v1::RegistrationParams& message);

void result_to_proto(const RegistrationResult& result, v1::RegistrationResult* message);

// Row-major 4x4 -> 16 repeated doubles.
void matrix_to_proto(const Eigen::Matrix4d& matrix, google::protobuf::RepeatedField<double>* values);

}  // namespace k4reg::service
