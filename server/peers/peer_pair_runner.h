// k4reg-server --peers: the coordinating replica's PairRunner. It sends a project's pairs to the peers (a gRPC
// target such as dns:///k4reg-headless.NS.svc.cluster.local:50051, round robin over its addresses) through
// RegisterPair, at most `in_flight` pairs at once.
//
// What travels: both clouds of the pair as this replica holds them after reading (float32 x, y, z in a local
// frame, float32 intensity when the scan has it, the frame's double origin) and every registration parameter:
// 12 bytes per point, 16 with intensity, plus about 150 bytes; 34 MB for a pair of 1 M-point scans with
// intensity. Each scan is encoded once per project. The peer computes register_clouds on exactly these numbers,
// so the poses equal the in-process ones bit for bit.
//
// A peer's reply is used only when it is a well-formed answer to the pair asked (peer_reply.h); a call past
// PeerOptions::call_timeout_s or with a reply that is not is a failed call.
// Nothing is lost: a call that fails (peer gone, draining, killed mid-pair) is sent again after a backoff, to
// whichever peer the channel picks; RESOURCE_EXHAUSTED (the peer's pair queue is full) is backpressure: wait and
// retry, counted as one failure only every 20 waits. After `attempts` failures, or when the pair is larger than a
// peer accepts (max_pair_bytes), the pair runs here. The coordinator's cancellation or deadline cancels every
// outstanding call within 50 ms.
#pragma once

#include <grpcpp/channel.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "k4reg/project/pair_runner.h"

namespace k4reg::service {

class Metrics;

struct PeerOptions {
  int in_flight = 4;                       // pairs out at once
  int attempts = 3;                        // failed calls (not RESOURCE_EXHAUSTED) before a pair runs here
  double first_backoff_s = 0.2;            // doubled after each retry, at most max_backoff_s
  double max_backoff_s = 5.0;
  std::uint64_t max_pair_bytes = 1ull << 30;  // the peers' --max-pair-mb: larger pairs run here
  double call_timeout_s = 900;             // --peer-timeout-s: one pair call's deadline (a peer that stalls fails it)
  std::string token;                       // --peer-token: sent with pair jobs and required of them; "" = none
};

// Who is asking: every pair call carries the project's request id (x-request-id, so the peers' logs tie the
// pairs to the project) and the bearer token pair jobs need (PeerOptions::token, else the client token), if any.
struct PeerCaller {
  std::string request_id;
  std::string auth_token;
};

// Where a project's pairs ran.
struct PairPlacement {
  std::atomic<std::size_t> on_peers{0}, local{0}, retried{0};
};

class PeerPairRunner : public PairRunner {
 public:
  PeerPairRunner(std::shared_ptr<grpc::Channel> peers, const PeerOptions& options, PeerCaller caller, Metrics& metrics,
                 PairPlacement& placement);
  void run(const std::vector<PreparedScan>& scans, const std::vector<ScanPair>& pairs, const RegistrationParams& params,
           const CancellationToken* cancel, const Done& done) override;

 private:
  std::shared_ptr<grpc::Channel> peers_;
  PeerOptions options_;
  PeerCaller caller_;
  Metrics& metrics_;
  PairPlacement& placement_;
};

}  // namespace k4reg::service
