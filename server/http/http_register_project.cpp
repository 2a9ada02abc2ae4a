#include "http/http_register_project.h"

#include "http/http_event_stream.h"
#include "http/http_json.h"
#include "http/http_register.h"
#include "http/http_upload.h"
#include "api/project_convert.h"
#include "jobs/project_job.h"
#include "api/status_mapping.h"

namespace k4reg::service {

void handle_register_project(const ServiceContext& service, HttpExchange& exchange) {
  if (const grpc::Status status = check_register_headers(service, exchange.request); !status.ok()) {
    exchange.fail(status);
    return;
  }
  // What the job reads, owned by the job when the answer streams (the handler returns before it runs).
  struct Call {
    v1::RegisterProjectRequest request;  // owns inline cloud bytes
    UploadForm form;                     // owns spool files
    ProjectJob project;
  };
  auto call = std::make_shared<Call>();
  CallClock clock;
  try {
    if (exchange.request.is_multipart_form_data()) {
      clock.upload_start = CallClock::Clock::now();
      call->form = read_upload_form(exchange.body, service, FormKind::kProject);
      clock.upload_end = CallClock::Clock::now();
      call->project = make_project_job(call->form.clouds, call->form.params, call->form.preview_points);
    } else {
      from_json(exchange.body.read_all(json_body_limit(service)), call->request);
      call->project = project_job_from_proto(service, call->request);
    }
  } catch (...) {
    exchange.fail(status_from_current_exception());
    return;
  }
  if (wants_events(exchange.request)) {
    stream_job(service, exchange, clock, [call, &service](Job& job, StreamedCall& events) {
      const StageListener stages = [&events](const std::string& stage, v1::StageEvent::Phase phase, double fraction) {
        events.post_stage<v1::RegisterProjectEvent>(stage, phase, fraction);
      };
      const PairListener pairs = [&events](const ProjectLink& link, std::size_t index, std::size_t count) {
        v1::RegisterProjectEvent event;
        pair_event_to_proto(link, index, count, *event.mutable_pair());
        events.post(event);
      };
      v1::RegisterProjectEvent reply;
      const grpc::Status status =
          run_project_job(service, job, call->project, stages, pairs, events.clock, events.record, *reply.mutable_result());
      if (status.ok()) events.post(reply);
      return status;
    });
    return;
  }
  v1::RegisterProjectResponse reply;
  bool queue_full = false;
  const grpc::Status status = run_and_wait(
      service, clock,
      [&](Job& job) { return run_project_job(service, job, call->project, {}, {}, clock, exchange.record, reply); },
      queue_full);
  if (!status.ok()) {
    exchange.fail(status, queue_full);
    return;
  }
  exchange.reply(reply);
}

}  // namespace k4reg::service
