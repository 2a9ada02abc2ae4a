#include "enum_convert.h"

#include <string>

#include "k4reg/util/error.h"

namespace k4reg::api {

v1::KeypointSignal to_proto(KeypointSignal signal) {
  switch (signal) {
    case KeypointSignal::kAuto: return v1::KEYPOINT_SIGNAL_AUTO;
    case KeypointSignal::kIntensity: return v1::KEYPOINT_SIGNAL_INTENSITY;
    case KeypointSignal::kGeometric: return v1::KEYPOINT_SIGNAL_GEOMETRIC;
  }
  return v1::KEYPOINT_SIGNAL_UNSPECIFIED;
}

v1::CoarseMethod to_proto(CoarseMethod method) {
  switch (method) {
    case CoarseMethod::kKeypoint4pcs: return v1::COARSE_METHOD_KEYPOINT_4PCS;
    case CoarseMethod::kPlain4pcs: return v1::COARSE_METHOD_PLAIN_4PCS;
  }
  return v1::COARSE_METHOD_UNSPECIFIED;
}

v1::FreeSpaceCheck to_proto(FreeSpaceCheck check) {
  switch (check) {
    case FreeSpaceCheck::kAuto: return v1::FREE_SPACE_CHECK_AUTO;
    case FreeSpaceCheck::kOn: return v1::FREE_SPACE_CHECK_ON;
    case FreeSpaceCheck::kOff: return v1::FREE_SPACE_CHECK_OFF;
  }
  return v1::FREE_SPACE_CHECK_UNSPECIFIED;
}

KeypointSignal from_proto(v1::KeypointSignal signal) {
  switch (signal) {
    case v1::KEYPOINT_SIGNAL_UNSPECIFIED: return RegistrationParams{}.signal;
    case v1::KEYPOINT_SIGNAL_AUTO: return KeypointSignal::kAuto;
    case v1::KEYPOINT_SIGNAL_INTENSITY: return KeypointSignal::kIntensity;
    case v1::KEYPOINT_SIGNAL_GEOMETRIC: return KeypointSignal::kGeometric;
    default: fail(ErrorCode::kInvalidArgument, "params.signal: unknown value " + std::to_string(signal));
  }
}

CoarseMethod from_proto(v1::CoarseMethod method) {
  switch (method) {
    case v1::COARSE_METHOD_UNSPECIFIED: return RegistrationParams{}.method;
    case v1::COARSE_METHOD_KEYPOINT_4PCS: return CoarseMethod::kKeypoint4pcs;
    case v1::COARSE_METHOD_PLAIN_4PCS: return CoarseMethod::kPlain4pcs;
    default: fail(ErrorCode::kInvalidArgument, "params.method: unknown value " + std::to_string(method));
  }
}

FreeSpaceCheck from_proto(v1::FreeSpaceCheck check) {
  switch (check) {
    case v1::FREE_SPACE_CHECK_UNSPECIFIED: return RegistrationParams{}.free_space;
    case v1::FREE_SPACE_CHECK_AUTO: return FreeSpaceCheck::kAuto;
    case v1::FREE_SPACE_CHECK_ON: return FreeSpaceCheck::kOn;
    case v1::FREE_SPACE_CHECK_OFF: return FreeSpaceCheck::kOff;
    default: fail(ErrorCode::kInvalidArgument, "params.free_space: unknown value " + std::to_string(check));
  }
}

}  // namespace k4reg::api
