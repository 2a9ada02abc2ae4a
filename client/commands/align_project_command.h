// `k4reg align-project SCAN...`: local project registration (no server).
#pragma once

#include <CLI/CLI.hpp>

namespace k4reg::cli {

void add_align_project_command(CLI::App& app);

}  // namespace k4reg::cli
