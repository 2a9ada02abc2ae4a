// What both RPC reactors share: the limits, the queue and the steps every call goes through
// (admission, deadlines, path resolution, reply decoration).
#pragma once

#include <grpcpp/server_context.h>

#include <chrono>
#include <memory>
#include <string>

#include "job_queue.h"
#include "k4reg/v1/registration.pb.h"
#include "memory_budget.h"
#include "path_policy.h"
#include "registration_job.h"
#include "request_log.h"
#include "spool.h"

namespace k4reg::service {

struct ServiceContext {
  JobQueue& queue;
  MemoryBudget& memory;
  const PathPolicy& paths;
  SpoolDir& spool;
  JobLimits limits;
  std::string auth_token;
  std::uint64_t max_upload_bytes = 0;
  v1::ServerInfo server_info;

  // Auth, then draining: UNAUTHENTICATED / UNAVAILABLE, else OK.
  grpc::Status admit(const grpc::ServerContextBase& context) const;
  // Queues the job; RESOURCE_EXHAUSTED when the queue is full, UNAVAILABLE when draining.
  grpc::Status submit(std::shared_ptr<Job> job, std::size_t& position) const;
  // A file reference as the worker will read it (throws k4reg::Error, see PathPolicy::resolve).
  CloudSource referenced_cloud(const std::string& path) const;
};

// The client's deadline becomes the job's deadline, so an expired call stops its CPU work.
void apply_deadline(const grpc::ServerContextBase& context, CancellationToken& token);

// The moments of a call from which ServerTimings are computed.
struct CallClock {
  using Clock = std::chrono::steady_clock;
  Clock::time_point call_start = Clock::now(), upload_start, upload_end, enqueued, job_start, job_end;
};

// Fills timings, server info and request id of a successful reply; call just before handing it to gRPC.
void decorate_reply(const ServiceContext& service, const CallClock& clock, const JobReport& report,
                    const std::string& request_id, v1::RegisterResponse& reply);

// The worker's side of a call, the same for both RPCs: runs the registration, times it on `clock`, notes
// points and times in `record`, and on success fills and decorates `reply`. Returns the call's status.
grpc::Status run_job(const ServiceContext& service, Job& job, const CloudSource& source, const CloudSource& target,
                     const RegistrationParams& params, const StageListener& listener, CallClock& clock,
                     RequestRecord& record, v1::RegisterResponse& reply);

}  // namespace k4reg::service
