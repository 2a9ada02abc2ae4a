// The project result as the service sends it -> the core's struct, so `register-project` prints what
// `align-project` prints.
#pragma once

#include "k4reg/project/project_registration.h"
#include "k4reg/v1/registration.pb.h"

namespace k4reg::cli {

ProjectResult project_result_from_proto(const v1::ProjectResult& message);

}  // namespace k4reg::cli
