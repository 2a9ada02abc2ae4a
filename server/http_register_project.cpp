#include "http_register_project.h"

#include "http_json.h"
#include "http_register.h"
#include "project_job.h"
#include "status_mapping.h"

namespace k4reg::service {

void handle_register_project(const ServiceContext& service, HttpExchange& exchange) {
  if (const grpc::Status status = check_register_headers(service, exchange.request); !status.ok()) {
    exchange.fail(status);
    return;
  }
  CallClock clock;
  v1::RegisterProjectRequest request;  // owns inline cloud bytes
  ProjectJob project;
  try {
    if (exchange.request.is_multipart_form_data())
      fail(ErrorCode::kInvalidArgument, "POST /v1/register-project takes application/json (scans by path or inline)");
    from_json(exchange.body.read_all(json_body_limit(service)), request);
    project = project_job_from_proto(service, request);
  } catch (...) {
    exchange.fail(status_from_current_exception());
    return;
  }
  v1::RegisterProjectResponse reply;
  bool queue_full = false;
  const grpc::Status status = run_and_wait(
      service, clock,
      [&](Job& job) { return run_project_job(service, job, project, {}, {}, clock, exchange.record, reply); },
      queue_full);
  if (!status.ok()) {
    exchange.fail(status, queue_full);
    return;
  }
  exchange.reply(reply);
}

}  // namespace k4reg::service
