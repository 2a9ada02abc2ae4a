// RegisterPair (unary, between replicas): a project's pair sent by a coordinating replica (peer_pair_runner.h).
// Each cloud comes inline, exactly as the coordinator holds it, or as the digest of one this replica keeps from an
// earlier pair (scan_cache.h), with its voxels and keypoints. The job runs on the pair pool (its own workers and
// queue), so replicas that all coordinate projects still serve each other's pairs. A cancelled or expired call
// takes its job out of the queue, or stops it running.
#pragma once

#include <grpcpp/support/server_callback.h>

#include <atomic>
#include <memory>

#include "observability/request_log.h"
#include "service_context.h"

namespace k4reg::service {

class PairReactor final : public grpc::ServerUnaryReactor {
 public:
  PairReactor(ServiceContext& service, grpc::CallbackServerContext* context, const v1::RegisterPairRequest* request,
              v1::RegisterPairResponse* reply);

  void OnCancel() override;
  void OnDone() override;

 private:
  void execute(Job& job);  // on a pair worker
  // The scan a PairCloud stands for: sent now (then kept), or held since an earlier pair (by digest). Throws
  // k4reg::Error: kNotFound for a digest not held, kInvalidArgument for a digest that does not match.
  std::shared_ptr<const ScanCache::Scan> held_scan(const v1::PairCloud& message);
  void finish(const grpc::Status& status);

  ServiceContext& service_;
  v1::RegisterPairResponse* reply_;
  RequestRecord record_;
  RegistrationParams params_;
  std::shared_ptr<const ScanCache::Scan> source_, target_;
  std::shared_ptr<Job> job_;
  std::atomic<bool> finished_{false};
};

}  // namespace k4reg::service
