// k4reg-server --peers: the coordinating replica's PairRunner. It sends a project's pairs to the peers (a gRPC
// target such as dns:///k4reg-headless.NS.svc.cluster.local:50051, round robin over its addresses) through
// RegisterPair, with both clouds inline (12 bytes per point, 16 with intensity: about 34 MB for a pair of 1 M-point
// scans with intensity), at most `in_flight` pairs at once. Nothing is lost: a peer that fails, drains or dies
// mid-pair has the pair sent again after a backoff (RESOURCE_EXHAUSTED is backpressure: wait, do not count it), and
// after `attempts` failures the pair runs here. The coordinator's cancellation cancels every outstanding call.
// The peers compute register_clouds on the coordinator's own numbers, so the poses equal the in-process ones.
#pragma once

#include <grpcpp/channel.h>

#include <atomic>
#include <memory>
#include <string>

#include "k4reg/project/pair_runner.h"
#include "metrics.h"

namespace k4reg::service {

struct PeerOptions {
  int in_flight = 4;            // pairs out at once
  int attempts = 3;             // failed calls (not RESOURCE_EXHAUSTED) before a pair runs locally
  double first_backoff_s = 0.2; // doubled after each try, at most max_backoff_s
  double max_backoff_s = 5.0;
  std::string request_id;       // the project's: every pair call carries it (x-request-id), so logs tie them
  std::string auth_token;       // sent to the peers when the deployment requires one
};

// Where a project's pairs ran.
struct PairPlacement {
  std::atomic<std::size_t> on_peers{0}, local{0}, retried{0};
};

class PeerPairRunner : public PairRunner {
 public:
  PeerPairRunner(std::shared_ptr<grpc::Channel> peers, PeerOptions options, PairPlacement& placement);
  void run(const std::vector<PointCloud>& scans, const std::vector<ScanPair>& pairs, const RegistrationParams& params,
           const CancellationToken* cancel, const Done& done) override;

 private:
  std::shared_ptr<grpc::Channel> peers_;
  PeerOptions options_;
  PairPlacement& placement_;
};

}  // namespace k4reg::service
