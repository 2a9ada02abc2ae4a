#include "service_context.h"

#include "auth.h"
#include "proto_convert.h"
#include "status_mapping.h"

namespace k4reg::service {
namespace {

double seconds(CallClock::Clock::duration d) { return std::chrono::duration<double>(d).count(); }

}  // namespace

grpc::Status ServiceContext::admit(const grpc::ServerContextBase& context) const {
  grpc::Status status = check_bearer_token(context, auth_token);
  if (!status.ok()) return status;
  if (!queue.accepting()) return {grpc::StatusCode::UNAVAILABLE, "server is draining; retry on another replica"};
  return grpc::Status::OK;
}

grpc::Status ServiceContext::submit(std::shared_ptr<Job> job, std::size_t& position) const {
  const JobQueue::Submission submission = queue.submit(std::move(job));
  position = submission.position;
  switch (submission.admission) {
    case JobQueue::Admission::kAccepted:
      return grpc::Status::OK;
    case JobQueue::Admission::kQueueFull:
      return {grpc::StatusCode::RESOURCE_EXHAUSTED,
              "job queue full (" + std::to_string(queue.capacity()) + " waiting, --queue-size); retry later"};
    case JobQueue::Admission::kDraining:
      break;
  }
  return {grpc::StatusCode::UNAVAILABLE, "server is draining; retry on another replica"};
}

CloudSource ServiceContext::referenced_cloud(const std::string& path) const { return {path, paths.resolve(path), {}}; }

void apply_deadline(const grpc::ServerContextBase& context, CancellationToken& token) {
  const auto deadline = context.deadline();
  if (deadline == std::chrono::system_clock::time_point::max()) return;
  // The token runs on the steady clock; carry the remaining time over.
  token.set_deadline(std::chrono::steady_clock::now() +
                     std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                         deadline - std::chrono::system_clock::now()));
}

void decorate_reply(const ServiceContext& service, const CallClock& clock, const JobReport& report,
                    const std::string& request_id, v1::RegisterResponse& reply) {
  v1::ServerTimings& t = *reply.mutable_timings();
  t.set_queue_wait_s(seconds(clock.job_start - clock.enqueued));
  t.set_request_to_job_start_s(seconds(clock.job_start - clock.call_start));
  t.set_upload_s(seconds(clock.upload_end - clock.upload_start));
  t.set_load_s(report.load_s);
  t.set_registration_s(report.registration_s);
  t.set_job_end_to_reply_s(seconds(CallClock::Clock::now() - clock.job_end));
  *reply.mutable_server() = service.server_info;
  reply.set_request_id(request_id);
}

grpc::Status run_job(const ServiceContext& service, Job& job, const CloudSource& source, const CloudSource& target,
                     const RegistrationParams& params, const StageListener& listener, CallClock& clock,
                     RequestRecord& record, v1::RegisterResponse& reply) {
  clock.job_start = CallClock::Clock::now();
  JobReport report;
  grpc::Status status;
  try {
    const RegistrationResult result =
        run_registration(source, target, params, service.limits, service.memory, job.token(), listener, report);
    result_to_proto(result, reply.mutable_result());
  } catch (...) {
    status = status_from_current_exception();
  }
  clock.job_end = CallClock::Clock::now();
  record.source_points = report.source_points;
  record.target_points = report.target_points;
  record.queue_wait_s = std::chrono::duration<double>(clock.job_start - clock.enqueued).count();
  record.registration_s = report.registration_s;
  if (status.ok()) decorate_reply(service, clock, report, record.request_id, reply);
  return status;
}

}  // namespace k4reg::service
