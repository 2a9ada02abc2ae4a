#include "project_reactor.h"

#include "project_convert.h"
#include "status_mapping.h"

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

void ProjectReactor::execute(Job& job) {
  const StageListener stages = [this](const std::string& stage, v1::StageEvent::Phase phase, double fraction) {
    post_stage(stage, phase, fraction, clock_.job_start);
  };
  const PairListener pairs = [this](const ProjectLink& link, std::size_t index, std::size_t count) {
    v1::RegisterProjectEvent message;
    pair_event_to_proto(link, index, count, *message.mutable_pair());
    post(std::move(message));
  };
  v1::RegisterProjectEvent reply;
  const grpc::Status status =
      run_project_job(service_, job, project_, stages, pairs, clock_, record_, *reply.mutable_result());
  if (status.ok()) post(std::move(reply));
  finish(status);
}

void ProjectReactor::on_finishing(const grpc::Status& status) {
  record_.code = status.error_code();
  record_.error = status.error_message();
  service_.end_request(record_);  // before the status leaves: a client that got its answer finds the log line
}

void ProjectReactor::OnDone() { delete this; }

}  // namespace k4reg::service
