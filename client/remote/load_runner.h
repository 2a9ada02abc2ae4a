// The engine of `k4reg load`: unary Register calls in a closed loop (N callers, each sending its next request
// when the previous one returns) or an open loop (a fixed arrival rate, whatever the completions).
#pragma once

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "remote/channel.h"
#include "k4reg/v1/registration.grpc.pb.h"

namespace k4reg::cli {

struct LoadPlan {
  std::vector<v1::RegisterRequest> requests;  // sent round robin
  int concurrency = 1;                        // closed loop: calls in flight
  double rate = 0;                            // > 0: open loop at this many calls per second
  std::size_t total = 20;                     // calls to send; 0 = as many as fit in duration_s
  double duration_s = 0;
  double deadline_s = 120;  // per call, so a run always ends
};

struct CallRecord {
  grpc::StatusCode code = grpc::StatusCode::OK;
  // From the call's start, or in the open loop from its scheduled start: a late dispatch counts as latency
  // (no coordinated omission).
  double latency_s = 0;
  std::optional<v1::ServerTimings> timings;  // OK calls
  std::string server_id;                     // OK calls
};

struct LoadOutcome {
  std::vector<CallRecord> calls;  // in completion order
  double wall_s = 0;              // first dispatch -> last completion
  double cpu_s = 0;               // user + system time of this process (all of gRPC's threads) over the run
  std::string first_failure;      // one-line description of the first call that failed, if any
};

LoadOutcome run_load(const std::shared_ptr<grpc::Channel>& channel, const ConnectionOptions& connection,
                     const LoadPlan& plan);

}  // namespace k4reg::cli
