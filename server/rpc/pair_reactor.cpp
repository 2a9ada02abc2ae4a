#include "rpc/pair_reactor.h"

#include "k4reg/util/error.h"
#include "api/proto_convert.h"
#include "api/status_mapping.h"
#include "status_name.h"

namespace k4reg::service {

PairReactor::PairReactor(ServiceContext& service, grpc::CallbackServerContext* context,
                         const v1::RegisterPairRequest* request, v1::RegisterPairResponse* reply)
    : service_(service), reply_(reply) {
  record_ = open_request(*context, "/k4reg.v1.Registration/RegisterPair");
  if (const grpc::Status status = service_.admit_pair(*context); !status.ok()) {
    finish(status);
    return;
  }
  try {
    params_ = params_from_proto(request->params());
    source_ = held_scan(request->source());
    target_ = held_scan(request->target());
  } catch (...) {
    finish(status_from_current_exception());
    return;
  }
  record_.source_points = source_->cloud.size();
  record_.target_points = target_->cloud.size();
  job_ = std::make_shared<Job>([this](Job& job) { execute(job); });
  apply_deadline(*context, job_->token());
  std::size_t position = 0;
  // From here on a worker may already be running the job: touch nothing it uses.
  if (const grpc::Status status = service_.submit_pair(job_, position); !status.ok()) finish(status);
}

std::shared_ptr<const ScanCache::Scan> PairReactor::held_scan(const v1::PairCloud& message) {
  const std::string name = message.name().empty() ? "a pair cloud" : message.name();
  if (message.points_xyz().empty() && !message.digest().empty()) {
    auto held = service_.pair_scans.find(message.digest());
    if (!held) fail(ErrorCode::kNotFound, name + " is not held here: send its points");
    return held;
  }
  const std::string digest = cloud_digest(message);
  if (!message.digest().empty() && message.digest() != digest)
    fail(ErrorCode::kInvalidArgument, name + ": the digest does not match the points");
  return service_.pair_scans.insert(digest, cloud_from_proto(message, service_.limits.max_points));
}

void PairReactor::execute(Job& job) {
  grpc::Status status;
  try {
    job.token().throw_if_stopped();  // cancelled or expired while queued
    // No waiting for memory: the coordinator's project may be what holds it (here or on its replica), so a busy
    // budget is backpressure the coordinator answers by trying elsewhere or later.
    const auto reservation =
        service_.memory.try_reserve(kBytesPerPoint * (source_->cloud.size() + target_->cloud.size()));
    if (!reservation) fail(ErrorCode::kResourceExhausted, "the memory budget is in use by other jobs; try again later");
    if (params_.threads == 0 || params_.threads > service_.limits.job_threads) params_.threads = service_.limits.job_threads;
    result_to_proto(register_clouds(source_->prepared, target_->prepared, params_, &job.token()),
                    reply_->mutable_result());
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
  // No job runs on the scans any more: the cache counts what the pair prepared on them, and may let them go.
  service_.pair_scans.release(std::move(source_));
  service_.pair_scans.release(std::move(target_));
  record_.code = status.error_code();
  record_.error = status.error_message();
  service_.metrics.pair_job_received(status_code_name(status.error_code()));
  service_.end_request(record_);
  Finish(status);
}

void PairReactor::OnDone() { delete this; }

}  // namespace k4reg::service
