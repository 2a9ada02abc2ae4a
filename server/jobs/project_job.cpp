#include "jobs/project_job.h"


#include <fmt/format.h>

#include <set>

#include "jobs/cloud_bytes.h"
#include "k4reg/util/error.h"
#include "k4reg/util/stopwatch.h"
#include "peers/peer_pair_runner.h"
#include "api/project_convert.h"
#include "api/proto_convert.h"
#include "api/status_mapping.h"

namespace k4reg::service {
namespace {

}  // namespace

ProjectOutcome run_project(const ProjectJob& project, const JobLimits& limits, MemoryBudget& memory,
                           const CancellationToken& token, const StageListener& stages, const PairListener& pairs,
                           PairRunner* runner, ProjectReport& report) {
  const std::vector<CloudSource>& scans = project.scans;
  token.throw_if_stopped();  // cancelled or expired while queued
  StageTracker progress(stages);
  const auto load_start = SteadyClock::now();
  progress("load", 0.0);
  const ReadOptions options{limits.max_points};
  std::vector<CloudBytes> bytes;
  std::uint64_t declared = 0;
  for (const CloudSource& scan : scans) {
    bytes.emplace_back(scan);
    declared += declared_cloud_points(scan, bytes.back().bytes(), options);
  }
  limits.check_project_points(declared);
  // Reserved before decoding, for every scan at once: they stay in memory for the whole project (one pair at a
  // time works on two of them), and a job holding some while it waits for more could wait for another such job.
  const MemoryBudget::Reservation reservation = memory.reserve(kBytesPerPoint * declared, token);
  std::vector<PointCloud> clouds;
  for (std::size_t i = 0; i < scans.size(); ++i) {
    clouds.push_back(load_cloud(scans[i], bytes[i].bytes(), options));
    report.points += clouds.back().size();
    progress("load", static_cast<double>(clouds.size()) / scans.size());
    token.throw_if_stopped();
  }
  bytes.clear();
  progress("load", 1.0);
  report.load_s = seconds_since(load_start);

  ProjectParams params = project.params;
  if (params.pairwise.threads == 0 || params.pairwise.threads > limits.job_threads) params.pairwise.threads = limits.job_threads;
  const auto start = SteadyClock::now();
  const ProgressCallback callback = [&](const std::string& stage, double fraction) { progress(stage, fraction); };
  ProjectOutcome outcome{register_project(clouds, params, &token, callback, pairs, runner), std::nullopt};
  report.registration_s = seconds_since(start);
  outcome.preview = preview_stage(project.preview_points, progress, [&](const PreviewParams& preview) {
    return make_project_preview(clouds, project.names, outcome.result, preview, &token);
  });
  return outcome;
}

ProjectJob make_project_job(std::vector<CloudSource> scans, const v1::ProjectParams& params, std::uint32_t preview_points) {
  ProjectJob job;
  job.params = project_params_from_proto(params);
  job.preview_points = preview_points_from_proto(preview_points);
  if (scans.size() < 2)
    fail(ErrorCode::kInvalidArgument, fmt::format("a project needs at least 2 scans, got {}", scans.size()));
  std::set<std::string> files;
  for (std::size_t i = 0; i < scans.size(); ++i) {
    if (!scans[i].file.empty() && !files.insert(scans[i].file).second)
      fail(ErrorCode::kInvalidArgument, fmt::format("scan {} ({}) is given twice: each scan once", i, scans[i].name));
    job.names.push_back(scans[i].name);
  }
  job.scans = std::move(scans);
  if (job.params.reference >= job.scans.size())
    fail(ErrorCode::kInvalidArgument, fmt::format("params.reference {} is out of range: the project has {} scans",
                                                  job.params.reference, job.scans.size()));
  return job;
}

ProjectJob project_job_from_proto(const ServiceContext& service, const v1::RegisterProjectRequest& request) {
  service.limits.check_project_scans(static_cast<std::size_t>(request.scans_size()));
  std::vector<CloudSource> scans;
  for (int i = 0; i < request.scans_size(); ++i)
    scans.push_back(service.cloud_source(request.scans(i), fmt::format("scan {}", i).c_str()));
  return make_project_job(std::move(scans), request.params(), request.preview_points());
}

grpc::Status run_project_job(const ServiceContext& service, Job& job, const ProjectJob& project, const StageListener& stages,
                             const PairListener& pairs, CallClock& clock, RequestRecord& record,
                             v1::RegisterProjectResponse& reply) {
  clock.job_start = CallClock::Clock::now();
  ProjectReport report;
  PairPlacement placement;
  grpc::Status status;
  try {
    // With --peers the pairs go out to the deployment; the poses are the same either way.
    std::optional<PeerPairRunner> runner;
    if (service.peers)
      runner.emplace(service.peers, service.peer_options, PeerCaller{record.request_id, service.pair_token()},
                     service.metrics, placement);
    const ProjectOutcome outcome = run_project(project, service.limits, service.memory, job.token(), stages, pairs,
                                               runner ? &*runner : nullptr, report);
    if (!runner) placement.local = outcome.result.links.size();  // one link per pair
    project_result_to_proto(outcome.result, project.names, reply.mutable_result());
    if (outcome.preview) preview_to_proto(*outcome.preview, reply.mutable_preview());
  } catch (...) {
    status = status_from_current_exception();
  }
  clock.job_end = CallClock::Clock::now();
  record.source_points = report.points;
  record.queue_wait_s = seconds(clock.job_start - clock.enqueued);
  record.registration_s = report.registration_s;
  service.metrics.observe_job(record.queue_wait_s, seconds(clock.job_end - clock.job_start), report.points);
  if (status.error_code() == grpc::StatusCode::CANCELLED || status.error_code() == grpc::StatusCode::DEADLINE_EXCEEDED)
    service.metrics.job_cancelled();
  if (status.ok()) {
    fill_timings(clock, report.load_s, report.registration_s, *reply.mutable_timings());
    reply.set_pairs_on_peers(static_cast<std::uint32_t>(placement.on_peers.load()));
    reply.set_pairs_local(static_cast<std::uint32_t>(placement.local.load()));
    reply.set_pair_retries(static_cast<std::uint32_t>(placement.retried.load()));
    *reply.mutable_server() = service.server_info;
    reply.set_request_id(record.request_id);
  }
  return status;
}

}  // namespace k4reg::service
