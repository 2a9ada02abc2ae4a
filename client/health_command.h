// `k4reg health --server HOST:PORT`: grpc.health.v1 checks; exit code 0 when every checked service is SERVING,
// so it works as a container health check.
#pragma once

#include <CLI/CLI.hpp>

namespace k4reg::cli {

void add_health_command(CLI::App& app);

}  // namespace k4reg::cli
