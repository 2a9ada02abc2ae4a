// The registration parameters' enums, core <-> k4reg.v1: one mapping for the client (flags it sends), the
// server (requests it reads) and a coordinating replica (the parameters it sends its peers).
#pragma once

#include "k4reg/registration/registration.h"
#include "k4reg/v1/registration.pb.h"

namespace k4reg::api {

v1::KeypointSignal to_proto(KeypointSignal signal);
v1::CoarseMethod to_proto(CoarseMethod method);
v1::FreeSpaceCheck to_proto(FreeSpaceCheck check);

// UNSPECIFIED gives the core's default; an unknown value throws k4reg::Error(kInvalidArgument) naming the
// field as params.signal, params.method or params.free_space.
KeypointSignal from_proto(v1::KeypointSignal signal);
CoarseMethod from_proto(v1::CoarseMethod method);
FreeSpaceCheck from_proto(v1::FreeSpaceCheck check);

}  // namespace k4reg::api
