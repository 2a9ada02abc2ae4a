// `k4reg align SOURCE TARGET`: local registration (no server).
#pragma once

#include <CLI/CLI.hpp>

namespace k4reg::cli {

void add_align_command(CLI::App& app);

}  // namespace k4reg::cli
