// k4reg.v1 PairSelection <-> k4reg::PairSelection, both ways: the client sends it, the server reads it and
// answers with the selection it used.
#pragma once

#include "k4reg/project/candidate_pairs.h"
#include "k4reg/v1/registration.pb.h"

namespace k4reg::api {

v1::PairSelection pair_selection_to_proto(PairSelection selection);
// UNSPECIFIED is auto (the server's default). Throws k4reg::Error(kInvalidArgument) for an unknown value.
PairSelection pair_selection_from_proto(int selection);

}  // namespace k4reg::api
