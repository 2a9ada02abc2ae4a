// k4reg.v1 answers -> core structs, for whoever reads them: the k4reg client (Register, RegisterProject) and a
// coordinating replica (a peer's RegisterPair). One copy, so both read a result the same way.
// Malformed messages (a transform that is not 16 numbers, byte arrays that are not whole float32 values) throw
// k4reg::Error(kInvalidArgument) naming what is wrong.
#pragma once

#include "k4reg/qa/cloud_preview.h"
#include "k4reg/registration/registration.h"
#include "k4reg/v1/registration.pb.h"

namespace k4reg::api {

// 16 numbers, row-major.
Eigen::Matrix4d matrix_from_proto(const google::protobuf::RepeatedField<double>& values);
// A translation constraint's 9 numbers (row-major); none (a peer of an older version) gives zero.
Eigen::Matrix3d constraint_from_proto(const google::protobuf::RepeatedField<double>& values);
// x, y, z of each point in turn.
std::vector<Eigen::Vector3d> points_from_proto(const google::protobuf::RepeatedField<double>& values);
ScannerPosition scanner_from_proto(const v1::ScannerPosition& message);
RegistrationResult result_from_proto(const v1::RegistrationResult& message);
CloudPreview preview_from_proto(const v1::Preview& message);

// Little-endian float32 values as the API's byte fields carry them (`what` names the field in errors).
std::vector<float> floats_from_bytes(const std::string& bytes, const std::string& what);
std::vector<Eigen::Vector3f> vectors_from_bytes(const std::string& bytes, const std::string& what);

}  // namespace k4reg::api
