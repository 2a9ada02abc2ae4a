#include "pair_reactor.h"

#include "k4reg/util/error.h"
#include "proto_convert.h"
#include "status_mapping.h"
#include "status_name.h"

namespace k4reg::service {

PairReactor::PairReactor(ServiceContext& service, grpc::CallbackServerContext* context,
                         const v1::RegisterPairRequest* request, v1::RegisterPairResponse* reply)
    : service_(service), reply_(reply) {
  record_ = open_request(*context, "/k4reg.v1.Registration/RegisterPair");
  if (const grpc::Status status = service_.admit(*context); !status.ok()) {
    finish(status);
    return;
  }
  try {
    params_ = params_from_proto(request->params());
    source_ = cloud_from_proto(request->source(), service_.limits.max_points);
    target_ = cloud_from_proto(request->target(), service_.limits.max_points);
  } catch (...) {
    finish(status_from_current_exception());
    return;
  }
  record_.source_points = source_.size();
  record_.target_points = target_.size();
  job_ = std::make_shared<Job>([this](Job& job) { execute(job); });
  apply_deadline(*context, job_->token());
  std::size_t position = 0;
  // From here on a worker may already be running the job: touch nothing it uses.
  if (const grpc::Status status = service_.submit_pair(job_, position); !status.ok()) finish(status);
}

void PairReactor::execute(Job& job) {
  grpc::Status status;
  try {
    job.token().throw_if_stopped();  // cancelled or expired while queued
    // No waiting for memory: the coordinator's project may be what holds it (here or on its replica), so a busy
    // budget is backpressure the coordinator answers by trying elsewhere or later.
    const auto reservation = service_.memory.try_reserve(kBytesPerPoint * (source_.size() + target_.size()));
    if (!reservation) fail(ErrorCode::kResourceExhausted, "the memory budget is in use by other jobs; try again later");
    if (params_.threads == 0 || params_.threads > service_.limits.job_threads) params_.threads = service_.limits.job_threads;
    result_to_proto(register_clouds(source_, target_, params_, &job.token()), reply_->mutable_result());
    *reply_->mutable_server() = service_.server_info;
  } catch (...) {
    status = status_from_current_exception();
  }
  finish(status);
}

void PairReactor::OnCancel() {
  if (!job_) return;  // refused before queueing; already finished
  job_->token().cancel();
  if (service_.withdraw_pair(job_.get())) finish({grpc::StatusCode::CANCELLED, "cancelled while queued"});
}

void PairReactor::finish(const grpc::Status& status) {
  if (finished_.exchange(true)) return;
  record_.code = status.error_code();
  record_.error = status.error_message();
  service_.metrics.pair_job_received(status_code_name(status.error_code()));
  service_.end_request(record_);
  Finish(status);
}

void PairReactor::OnDone() { delete this; }

}  // namespace k4reg::service
