// The server's own account of a call (ServerTimings), for `register --json` and the load report.
#pragma once

#include <nlohmann/json.hpp>

#include "k4reg/v1/registration.pb.h"

namespace k4reg::cli {

// Time the service itself added: call start -> job start without the queue wait and the upload, plus job
// end -> reply. What is left when capacity (queueing) and bandwidth (uploads) are taken out.
double server_overhead_s(const v1::ServerTimings& timings);

nlohmann::json server_timings_to_json(const v1::ServerTimings& timings);

}  // namespace k4reg::cli
