// `k4reg register SOURCE TARGET --server HOST:PORT`: the same job as `align`, run by the service.
#pragma once

#include <CLI/CLI.hpp>

namespace k4reg::cli {

void add_register_command(CLI::App& app);

}  // namespace k4reg::cli
