// `k4reg health [--server HOST:PORT]`: grpc.health.v1 checks; exit code 0 when every checked service is SERVING,
// so it works as a container health check. Without --server or $K4REG_SERVER it asks the server's health
// listener named by $K4REG_HEALTH_LISTEN (the image's HEALTHCHECK does).
#pragma once

#include <CLI/CLI.hpp>

namespace k4reg::cli {

void add_health_command(CLI::App& app);

}  // namespace k4reg::cli
