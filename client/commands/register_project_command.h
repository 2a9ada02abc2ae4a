// `k4reg register-project SCAN...`: project registration on a k4reg server (RegisterProject).
#pragma once

#include <CLI/CLI.hpp>

namespace k4reg::cli {

void add_register_project_command(CLI::App& app);

}  // namespace k4reg::cli
