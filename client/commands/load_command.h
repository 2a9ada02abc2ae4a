// `k4reg load --server HOST:PORT --pair SRC TGT`: a bounded load test of the service (closed or open loop)
// reporting what ghz reports, plus the server's own timings and the client's CPU use.
#pragma once

#include <CLI/CLI.hpp>

namespace k4reg::cli {

void add_load_command(CLI::App& app);

}  // namespace k4reg::cli
