// Register (unary): validate, resolve the clouds, queue the job and return; a worker runs the job and
// finishes the call. A cancelled or expired call takes its job out of the queue, or stops it running.
#pragma once

#include <grpcpp/support/server_callback.h>

#include <atomic>
#include <memory>

#include "observability/request_log.h"
#include "service_context.h"

namespace k4reg::service {

class RegisterReactor final : public grpc::ServerUnaryReactor {
 public:
  RegisterReactor(ServiceContext& service, grpc::CallbackServerContext* context, const v1::RegisterRequest* request,
                  v1::RegisterResponse* reply);

  void OnCancel() override;
  void OnDone() override;

 private:
  void execute(Job& job);  // on a worker
  void finish(const grpc::Status& status);

  ServiceContext& service_;
  v1::RegisterResponse* reply_;
  RequestRecord record_;
  CallClock clock_;
  PairJob pair_;
  std::shared_ptr<Job> job_;
  std::atomic<bool> finished_{false};
};

}  // namespace k4reg::service
