// What both RPC reactors and the HTTP API share: the limits, the queue, the metrics and the steps every call
// goes through (admission, deadlines, path resolution, reply decoration, the access log).
#pragma once

#include <grpcpp/server_context.h>

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "jobs/job_queue.h"
#include "k4reg/v1/registration.pb.h"
#include "jobs/memory_budget.h"
#include "observability/metrics.h"
#include "security/path_policy.h"
#include "peers/peer_pair_runner.h"
#include "jobs/registration_job.h"
#include "peers/scan_cache.h"
#include "observability/request_log.h"
#include "jobs/spool.h"
#include "rpc/upload_idle_watch.h"

namespace k4reg::service {

struct ServiceContext {
  JobQueue& queue;
  JobQueue& pair_queue;  // RegisterPair jobs from coordinating peers: their own workers, so projects cannot deadlock
  ScanCache& pair_scans;  // the scans of those pair jobs, with their preparation, by digest
  MemoryBudget& memory;
  const PathPolicy& paths;
  SpoolDir& spool;
  UploadIdleWatch& idle_uploads;
  JobLimits limits;
  std::string auth_token;
  std::uint64_t max_upload_bytes = 0;  // per uploaded file (RegisterStream, HTTP multipart)
  std::uint64_t max_inline_bytes = 0;  // per unary request (Register, HTTP JSON)
  v1::ServerInfo server_info;
  Metrics& metrics;

  // Auth, then draining: UNAUTHENTICATED / UNAVAILABLE, else OK. `authorization` as in check_bearer_token.
  grpc::Status admit(const grpc::ServerContextBase& context) const;
  grpc::Status admit(std::optional<std::string_view> authorization) const;
  // RegisterPair: the same with the token pair jobs need, so that where the deployment sets a --peer-token, a
  // client token alone cannot submit pair jobs.
  grpc::Status admit_pair(const grpc::ServerContextBase& context) const;
  const std::string& pair_token() const { return peer_options.token.empty() ? auth_token : peer_options.token; }
  // Readiness (gRPC "readiness" health, HTTP /readyz): UNAVAILABLE while draining or while the queue is full.
  grpc::Status readiness() const;
  // Queues the job; RESOURCE_EXHAUSTED when the queue is full, UNAVAILABLE when draining.
  grpc::Status submit(std::shared_ptr<Job> job, std::size_t& position) const;
  // Takes a job out of the queue before a worker picks it up (JobQueue::withdraw); true = it will never run.
  bool withdraw(const Job* job) const;
  // The same on the pair queue.
  grpc::Status submit_pair(std::shared_ptr<Job> job, std::size_t& position) const;
  bool withdraw_pair(const Job* job) const;
  // k4reg-server --peers: where project pairs go (null = in process), and how.
  std::shared_ptr<grpc::Channel> peers;
  PeerOptions peer_options;
  bool public_metrics = false;  // --public-metrics: HTTP /metrics and /v1/version need no token
  // Throws k4reg::Error(kResourceExhausted) for a Register or RegisterProject request over --max-inline-mb
  // (gRPC's own message limit is the larger --max-pair-mb, for RegisterPair).
  void check_inline_size(std::size_t bytes) const;
  // A file reference as the worker will read it (throws k4reg::Error, see PathPolicy::resolve).
  CloudSource referenced_cloud(const std::string& path) const;
  // A RegisterRequest's cloud: a reference or inline bytes (which the request owns). Throws k4reg::Error.
  CloudSource cloud_source(const v1::CloudInput& input, const char* role) const;
  // Ends a call of either protocol: the access-log line and the request metrics.
  void end_request(const RequestRecord& record) const;
};

// The client's deadline becomes the job's deadline, so an expired call stops its CPU work.
void apply_deadline(const grpc::ServerContextBase& context, CancellationToken& token);

// The moments of a call from which ServerTimings are computed.
struct CallClock {
  using Clock = std::chrono::steady_clock;
  Clock::time_point call_start = Clock::now(), upload_start, upload_end, enqueued, job_start, job_end;
};

// A stage event as both streams send it (Event: RegisterStreamResponse or RegisterProjectEvent, each carries one
// as `stage`), timed from the job's start.
template <typename Event>
Event make_stage_event(const std::string& stage, v1::StageEvent::Phase phase, double fraction, const CallClock& clock,
                       CallClock::Clock::time_point now) {
  Event event;
  v1::StageEvent& stage_event = *event.mutable_stage();
  stage_event.set_stage(stage);
  stage_event.set_phase(phase);
  stage_event.set_fraction(fraction);
  stage_event.set_elapsed_s(std::chrono::duration<double>(now - clock.job_start).count());
  return event;
}

inline double seconds(CallClock::Clock::duration d) { return std::chrono::duration<double>(d).count(); }

// The ServerTimings of a job that ran on `clock`; call just before the reply leaves.
void fill_timings(const CallClock& clock, double load_s, double registration_s, v1::ServerTimings& timings);

// Fills timings, server info and request id of a successful reply; call just before handing it to gRPC.
void decorate_reply(const ServiceContext& service, const CallClock& clock, const JobReport& report,
                    const std::string& request_id, v1::RegisterResponse& reply);

// The worker's side of a call, the same for both RPCs and HTTP: runs the registration, times it on `clock`,
// notes points and times in `record` and the metrics, and on success fills and decorates `reply`. Returns
// the call's status.
grpc::Status run_job(const ServiceContext& service, Job& job, const PairJob& pair, const StageListener& listener,
                     CallClock& clock, RequestRecord& record, v1::RegisterResponse& reply);

}  // namespace k4reg::service
