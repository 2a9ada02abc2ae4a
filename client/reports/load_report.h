// What `k4reg load` prints: throughput, latency percentiles and histogram, calls per status code, the server's
// own timings (to separate service overhead from queueing) and the client's CPU use — as text or JSON.
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <ostream>
#include <string>
#include <vector>

#include "reports/latency_stats.h"
#include "remote/load_runner.h"

namespace k4reg::cli {

struct LoadSummary {
  std::size_t calls = 0;
  double wall_s = 0, calls_per_s = 0;
  double client_cpu_percent = 0;  // of one core: near 100 % x cores means the client, not the server, is the limit
  // Latency of OK calls only: refusals such as RESOURCE_EXHAUSTED return in microseconds and would make an
  // overloaded server look fast. They are counted per status code instead.
  LatencySummary latency_s;
  std::vector<HistogramBucket> histogram;
  std::map<std::string, std::size_t> status_counts;  // "OK", "RESOURCE_EXHAUSTED", ...
  // From the OK responses' ServerTimings, in seconds.
  LatencySummary queue_wait_s, request_to_job_start_s, registration_s, job_end_to_reply_s, overhead_s;
  std::map<std::string, std::size_t> replies_per_server;  // server_id -> OK calls: how round robin spread them
};

LoadSummary summarize_load(const LoadOutcome& outcome);

nlohmann::json load_summary_to_json(const LoadPlan& plan, const LoadSummary& summary);
void print_load_summary(std::ostream& out, const LoadPlan& plan, const LoadSummary& summary);

}  // namespace k4reg::cli
