#include "rpc/register_reactor.h"

#include "api/proto_convert.h"
#include "api/status_mapping.h"

namespace k4reg::service {

RegisterReactor::RegisterReactor(ServiceContext& service, grpc::CallbackServerContext* context,
                                 const v1::RegisterRequest* request, v1::RegisterResponse* reply)
    : service_(service), reply_(reply) {
  record_ = open_request(*context, "/k4reg.v1.Registration/Register");
  if (const grpc::Status status = service_.admit(*context); !status.ok()) {
    finish(status);
    return;
  }
  try {
    service_.check_inline_size(request->ByteSizeLong());
    pair_.params = params_from_proto(request->params());
    pair_.preview_points = preview_points_from_proto(request->preview_points());
    pair_.source = service_.cloud_source(request->source(), "source");
    pair_.target = service_.cloud_source(request->target(), "target");
  } catch (...) {
    finish(status_from_current_exception());
    return;
  }
  job_ = std::make_shared<Job>([this](Job& job) { execute(job); });
  apply_deadline(*context, job_->token());
  clock_.enqueued = CallClock::Clock::now();
  std::size_t position = 0;
  // From here on a worker may already be running the job: touch nothing it uses.
  if (const grpc::Status status = service_.submit(job_, position); !status.ok()) finish(status);
}

void RegisterReactor::execute(Job& job) { finish(run_job(service_, job, pair_, {}, clock_, record_, *reply_)); }

void RegisterReactor::OnCancel() {
  if (!job_) return;  // refused before queueing; already finished
  job_->token().cancel();
  if (service_.withdraw(job_.get())) finish({grpc::StatusCode::CANCELLED, "cancelled while queued"});
}

void RegisterReactor::finish(const grpc::Status& status) {
  if (finished_.exchange(true)) return;
  record_.code = status.error_code();
  record_.error = status.error_message();
  service_.end_request(record_);  // before the reply leaves: a client that got its answer finds the log line
  Finish(status);
}

void RegisterReactor::OnDone() { delete this; }

}  // namespace k4reg::service
