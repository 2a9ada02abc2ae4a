// k4reg.v1 project messages <-> core project structs (RegisterProject and POST /v1/register-project).
#pragma once

#include <string>
#include <vector>

#include "k4reg/project/project_registration.h"
#include "k4reg/v1/registration.pb.h"

namespace k4reg::service {

// Unset fields take the core's defaults. Throws k4reg::Error(kInvalidArgument) naming the field for bad
// values (the pairwise ones as params_from_proto, prefixed "params.pairwise.").
ProjectParams project_params_from_proto(const v1::ProjectParams& message);

// files: each scan as the request named it.
void project_result_to_proto(const ProjectResult& result, const std::vector<std::string>& files, v1::ProjectResult* message);

// The event of the index-th of `pairs` pairs, registered as `link`.
void pair_event_to_proto(const ProjectLink& link, std::size_t index, std::size_t pairs, v1::PairEvent& event);

}  // namespace k4reg::service
