// What a worker does for one project request (RegisterProject, POST /v1/register-project): read every scan,
// reserve their memory, run the core's register_project with stage and pair events.
#pragma once

#include <functional>
#include <optional>
#include <vector>

#include "k4reg/project/project_registration.h"
#include "jobs/registration_job.h"
#include "service_context.h"

namespace k4reg::service {

// Filled as the job goes, so that a failed job still reports what it got to.
struct ProjectReport {
  std::uint64_t points = 0;  // all scans
  double load_s = 0, registration_s = 0;
};

// Called on the worker thread after each pair.
using PairListener = std::function<void(const ProjectLink& link, std::size_t index, std::size_t pairs)>;

// What a project job answers: the result and, when asked for (preview_points > 0), the preview.
struct ProjectOutcome {
  ProjectResult result;
  std::optional<CloudPreview> preview;
};

// A project request as the worker will run it: its scans (references resolved, inline bytes owned by the
// request) and parameters. Throws k4reg::Error for fewer than 2 scans, a scan given twice by path, bad
// parameters and the path errors of PathPolicy::resolve, so a malformed project is refused before it queues.
struct ProjectJob {
  std::vector<CloudSource> scans;
  std::vector<std::string> names;  // as the request named them
  ProjectParams params;
  std::size_t preview_points = 0;
};
ProjectJob make_project_job(std::vector<CloudSource> scans, const v1::ProjectParams& params, std::uint32_t preview_points);
ProjectJob project_job_from_proto(const ServiceContext& service, const v1::RegisterProjectRequest& request);

// Throws k4reg::Error: the first scan that cannot be read (named as the client named it), kInvalidArgument
// for a malformed project (fewer than 2 scans, a reference out of range, ...), kResourceExhausted over the
// memory budget, kCancelled / kDeadlineExceeded once the token fires. The preview is the last stage.
ProjectOutcome run_project(const ProjectJob& project, const JobLimits& limits, MemoryBudget& memory,
                           const CancellationToken& token, const StageListener& stages, const PairListener& pairs,
                           PairRunner* runner, ProjectReport& report);

// The worker's side of a project call, the same for gRPC and HTTP (cf. run_job): runs it, times it on
// `clock`, notes points and times in `record` and the metrics, and on success fills `reply`.
grpc::Status run_project_job(const ServiceContext& service, Job& job, const ProjectJob& project, const StageListener& stages,
                             const PairListener& pairs, CallClock& clock, RequestRecord& record,
                             v1::RegisterProjectResponse& reply);

}  // namespace k4reg::service
