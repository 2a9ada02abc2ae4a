// The registration parameter flags shared by `k4reg align` (local) and `k4reg register` (remote).
// Flag names follow the API fields: --min-scale is min_scale_m, --overlap is overlap, and so on.
#pragma once

#include <CLI/CLI.hpp>

#include "k4reg/registration.h"

namespace k4reg::cli {

void add_registration_flags(CLI::App& command, RegistrationParams& params);

}  // namespace k4reg::cli
