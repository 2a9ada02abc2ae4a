// What a coordinator checks of a peer's RegisterPair reply before it uses it: a peer may be an old or broken
// replica, or not a replica at all.
#pragma once

#include <cstddef>
#include <string>

#include "k4reg/v1/registration.pb.h"

namespace k4reg::service {

// Empty when `reply` is a result for a pair of clouds of these sizes: a rigid 4x4 transform, finite numbers
// throughout, the point counts of the clouds sent. Otherwise what is wrong, in words.
std::string reply_problem(const v1::RegisterPairResponse& reply, std::size_t source_points, std::size_t target_points);

}  // namespace k4reg::service
