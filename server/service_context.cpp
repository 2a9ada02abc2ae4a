#include "service_context.h"

#include <fmt/format.h>

#include "security/auth.h"
#include "k4reg/util/error.h"
#include "api/proto_convert.h"
#include "api/status_mapping.h"
#include "status_name.h"

namespace k4reg::service {
namespace {

constexpr const char* kDraining = "server is draining; retry on another replica";

}  // namespace

namespace {

// A call whose token checked out (`auth` OK) is admitted unless the server is draining.
grpc::Status admitted(grpc::Status auth, const JobQueue& queue) {
  if (!auth.ok()) return auth;
  if (!queue.accepting()) return {grpc::StatusCode::UNAVAILABLE, kDraining};
  return grpc::Status::OK;
}

}  // namespace

grpc::Status ServiceContext::admit(const grpc::ServerContextBase& context) const {
  return admitted(check_bearer_token(context, auth_token), queue);
}

grpc::Status ServiceContext::admit(std::optional<std::string_view> authorization) const {
  return admitted(check_bearer_token(authorization, auth_token), queue);
}

grpc::Status ServiceContext::admit_pair(const grpc::ServerContextBase& context) const {
  return admitted(check_bearer_token(context, pair_token()), queue);
}

grpc::Status ServiceContext::readiness() const {
  if (!queue.accepting()) return {grpc::StatusCode::UNAVAILABLE, kDraining};
  if (queue.full()) return {grpc::StatusCode::UNAVAILABLE, "job queue full (--queue-size)"};
  return grpc::Status::OK;
}

namespace {

grpc::Status submit_to(JobQueue& queue, Metrics& metrics, std::shared_ptr<Job> job, std::size_t& position) {
  const JobQueue::Submission submission = queue.submit(std::move(job));
  position = submission.position;
  switch (submission.admission) {
    case JobQueue::Admission::kAccepted:
      return grpc::Status::OK;
    case JobQueue::Admission::kQueueFull:
      metrics.job_rejected("queue_full");
      return {grpc::StatusCode::RESOURCE_EXHAUSTED,
              "job queue full (" + std::to_string(queue.capacity()) + " waiting, --queue-size); retry later"};
    case JobQueue::Admission::kDraining:
      break;
  }
  metrics.job_rejected("draining");
  return {grpc::StatusCode::UNAVAILABLE, kDraining};
}

bool withdraw_from(JobQueue& queue, Metrics& metrics, const Job* job) {
  if (!queue.withdraw(job)) return false;
  metrics.job_cancelled();
  return true;
}

}  // namespace

grpc::Status ServiceContext::submit(std::shared_ptr<Job> job, std::size_t& position) const {
  return submit_to(queue, metrics, std::move(job), position);
}

bool ServiceContext::withdraw(const Job* job) const { return withdraw_from(queue, metrics, job); }

grpc::Status ServiceContext::submit_pair(std::shared_ptr<Job> job, std::size_t& position) const {
  return submit_to(pair_queue, metrics, std::move(job), position);
}

bool ServiceContext::withdraw_pair(const Job* job) const { return withdraw_from(pair_queue, metrics, job); }

void ServiceContext::check_inline_size(std::size_t bytes) const {
  if (bytes > max_inline_bytes)
    fail(ErrorCode::kResourceExhausted, fmt::format("a request of {:.1f} MiB, more than {} MiB (--max-inline-mb): upload "
                                                    "large clouds with RegisterStream or reference them by path",
                                                    double(bytes) / (1 << 20), max_inline_bytes >> 20));
}

CloudSource ServiceContext::referenced_cloud(const std::string& path) const { return {path, paths.resolve(path), {}, &paths}; }

CloudSource ServiceContext::cloud_source(const v1::CloudInput& input, const char* role) const {
  switch (input.kind_case()) {
    case v1::CloudInput::kPath:
      return referenced_cloud(input.path());
    case v1::CloudInput::kInlineCloud: {
      const v1::InlineCloud& cloud = input.inline_cloud();
      return {cloud.file_name().empty() ? role : cloud.file_name(), {}, cloud.data()};
    }
    case v1::CloudInput::KIND_NOT_SET:
      break;
  }
  fail(ErrorCode::kInvalidArgument, std::string(role) + ": give either path or inline_cloud");
}

void ServiceContext::end_request(const RequestRecord& record) const {
  log_request(record);
  metrics.observe_request(record.protocol, record.method, status_code_name(record.code),
                          seconds(CallClock::Clock::now() - record.start), record.upload_bytes);
}

void apply_deadline(const grpc::ServerContextBase& context, CancellationToken& token) {
  const auto deadline = context.deadline();
  if (deadline == std::chrono::system_clock::time_point::max()) return;
  // The token runs on the steady clock; carry the remaining time over.
  token.set_deadline(std::chrono::steady_clock::now() +
                     std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                         deadline - std::chrono::system_clock::now()));
}

void fill_timings(const CallClock& clock, double load_s, double registration_s, v1::ServerTimings& t) {
  t.set_queue_wait_s(seconds(clock.job_start - clock.enqueued));
  t.set_request_to_job_start_s(seconds(clock.job_start - clock.call_start));
  t.set_upload_s(seconds(clock.upload_end - clock.upload_start));
  t.set_load_s(load_s);
  t.set_registration_s(registration_s);
  t.set_job_end_to_reply_s(seconds(CallClock::Clock::now() - clock.job_end));
}

void decorate_reply(const ServiceContext& service, const CallClock& clock, const JobReport& report,
                    const std::string& request_id, v1::RegisterResponse& reply) {
  fill_timings(clock, report.load_s, report.registration_s, *reply.mutable_timings());
  *reply.mutable_server() = service.server_info;
  reply.set_request_id(request_id);
}

grpc::Status run_job(const ServiceContext& service, Job& job, const PairJob& pair, const StageListener& listener,
                     CallClock& clock, RequestRecord& record, v1::RegisterResponse& reply) {
  clock.job_start = CallClock::Clock::now();
  JobReport report;
  grpc::Status status;
  try {
    const RegistrationOutcome outcome =
        run_registration(pair, service.limits, service.memory, job.token(), listener, report);
    result_to_proto(outcome.result, reply.mutable_result());
    if (outcome.preview) preview_to_proto(*outcome.preview, reply.mutable_preview());
  } catch (...) {
    status = status_from_current_exception();
  }
  clock.job_end = CallClock::Clock::now();
  record.source_points = report.source_points;
  record.target_points = report.target_points;
  record.queue_wait_s = seconds(clock.job_start - clock.enqueued);
  record.registration_s = report.registration_s;
  service.metrics.observe_job(record.queue_wait_s, seconds(clock.job_end - clock.job_start),
                              report.source_points + report.target_points);
  if (status.error_code() == grpc::StatusCode::CANCELLED || status.error_code() == grpc::StatusCode::DEADLINE_EXCEEDED)
    service.metrics.job_cancelled();
  if (status.ok()) decorate_reply(service, clock, report, record.request_id, reply);
  return status;
}

}  // namespace k4reg::service
