#include "rpc/project_reactor.h"

#include "api/project_convert.h"
#include "api/status_mapping.h"

namespace k4reg::service {

ProjectReactor::ProjectReactor(ServiceContext& service, grpc::CallbackServerContext* context,
                               const v1::RegisterProjectRequest* request)
    : JobStreamReactor(service) {
  record_ = open_request(*context, "/k4reg.v1.Registration/RegisterProject");
  if (const grpc::Status status = service_.admit(*context); !status.ok()) {
    finish(status);
    return;
  }
  try {
    service_.check_inline_size(request->ByteSizeLong());
    project_ = project_job_from_proto(service_, *request);  // inline bytes stay owned by the request
  } catch (...) {
    finish(status_from_current_exception());
    return;
  }
  start_job(*context, clock_, [this](Job& job) { execute(job); });
}

grpc::Status run_project_call(const ServiceContext& service, Job& job, const ProjectJob& project, CallClock& clock,
                              RequestRecord& record, const StageListener& stages,
                              const std::function<void(v1::RegisterProjectEvent)>& post) {
  const PairListener pairs = [&post](const ProjectLink& link, std::size_t index, std::size_t count) {
    v1::RegisterProjectEvent message;
    pair_event_to_proto(link, index, count, *message.mutable_pair());
    post(std::move(message));
  };
  v1::RegisterProjectEvent reply;
  const grpc::Status status = run_project_job(service, job, project, stages, pairs, clock, record, *reply.mutable_result());
  if (status.ok()) post(std::move(reply));
  return status;
}

void ProjectReactor::execute(Job& job) {
  finish(run_project_call(service_, job, project_, clock_, record_, stage_listener(clock_), poster()));
}

void ProjectReactor::on_finishing(const grpc::Status& status) {
  record_.code = status.error_code();
  record_.error = status.error_message();
  service_.end_request(record_);  // before the status leaves: a client that got its answer finds the log line
}

void ProjectReactor::OnDone() { delete this; }

}  // namespace k4reg::service
