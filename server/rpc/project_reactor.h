// RegisterProject (server streaming): the request names or carries every scan; the job runs on a worker,
// which posts the queued event, stage events ("load", "screen", "pairs", "selection", "refinement"), one event per
// registered pair, and finally the result, through the outbox (job_stream_reactor.h).
#pragma once

#include <functional>
#include <memory>

#include "rpc/job_stream_reactor.h"
#include "jobs/project_job.h"
#include "observability/request_log.h"
#include "service_context.h"

namespace k4reg::service {

// A project call's job on a worker (RegisterProject, RegisterProjectStream): runs it, posting its stage and
// pair events and, when it succeeds, the result; returns the call's status.
grpc::Status run_project_call(const ServiceContext& service, Job& job, const ProjectJob& project, CallClock& clock,
                              RequestRecord& record, const StageListener& stages,
                              const std::function<void(v1::RegisterProjectEvent)>& post);

class ProjectReactor final
    : public JobStreamReactor<grpc::ServerWriteReactor<v1::RegisterProjectEvent>, v1::RegisterProjectEvent> {
 public:
  ProjectReactor(ServiceContext& service, grpc::CallbackServerContext* context, const v1::RegisterProjectRequest* request);

  void OnDone() override;

 private:
  void execute(Job& job);  // on a worker
  void on_finishing(const grpc::Status& status) override;

  RequestRecord record_;
  CallClock clock_;
  ProjectJob project_;
};

}  // namespace k4reg::service
