// The registration parameter flags shared by `k4reg align` (local) and `k4reg register` (remote).
// Flag names follow the API fields: --min-scale is min_scale_m, --overlap is overlap, and so on.
#pragma once

#include <CLI/CLI.hpp>

#include "k4reg/registration/registration.h"

namespace k4reg::cli {

// The option behind each flag, so a remote command can tell which ones the user gave (Option::count()).
struct RegistrationFlags {
  CLI::Option *min_scale, *overlap, *no_icp, *one_sided, *levelled, *seed, *threads, *time_budget, *bases, *octaves, *scales_per_octave,
      *min_contrast, *signal, *free_space, *method, *plain_voxel;
};

RegistrationFlags add_registration_flags(CLI::App& command, RegistrationParams& params);

}  // namespace k4reg::cli
