#include "peers/peer_pair_runner.h"

#include <chrono>
#include <mutex>
#include <thread>

#include "k4reg/v1/registration.grpc.pb.h"
#include "messages_to_core.h"
#include "observability/metrics.h"
#include "peers/peer_reply.h"
#include "api/proto_convert.h"
#include "status_name.h"

namespace k4reg::service {
namespace {

using Clock = std::chrono::steady_clock;
constexpr int kMaxBackpressureWaits = 20;

// The calls in flight, so that the coordinator's cancellation reaches every one of them.
class OutstandingCalls {
 public:
  void add(grpc::ClientContext* context) {
    const std::lock_guard lock(mutex_);
    calls_.push_back(context);
    if (cancelled_) context->TryCancel();
  }
  void remove(grpc::ClientContext* context) {
    const std::lock_guard lock(mutex_);
    std::erase(calls_, context);
  }
  void cancel_all() {
    const std::lock_guard lock(mutex_);
    cancelled_ = true;
    for (grpc::ClientContext* context : calls_) context->TryCancel();
  }

 private:
  std::mutex mutex_;
  std::vector<grpc::ClientContext*> calls_;
  bool cancelled_ = false;
};

// A peer's answer that is the pair's own outcome (the same as running it here would give), not the peer's trouble.
bool is_pair_outcome(grpc::StatusCode code) {
  return code == grpc::StatusCode::FAILED_PRECONDITION || code == grpc::StatusCode::INVALID_ARGUMENT;
}

}  // namespace

PeerPairRunner::PeerPairRunner(std::shared_ptr<grpc::Channel> peers, const PeerOptions& options, PeerCaller caller,
                               Metrics& metrics, PairPlacement& placement)
    : peers_(std::move(peers)), options_(options), caller_(std::move(caller)), metrics_(metrics), placement_(placement) {}

void PeerPairRunner::run(const std::vector<PreparedScan>& scans, const std::vector<ScanPair>& pairs,
                         const RegistrationParams& params, const CancellationToken* cancel, const Done& done) {
  // Each scan is encoded once, whatever the number of pairs it is in; its digest stands for it where a peer holds
  // it from an earlier pair.
  std::vector<v1::PairCloud> clouds(scans.size()), digests(scans.size());
  for (std::size_t i = 0; i < scans.size(); ++i) {
    cloud_to_proto(scans[i].cloud(), "scan " + std::to_string(i), &clouds[i]);
    clouds[i].set_digest(cloud_digest(clouds[i]));
    digests[i].set_name(clouds[i].name());
    digests[i].set_digest(clouds[i].digest());
  }
  v1::RegistrationParams sent;
  params_to_proto(params, &sent);
  auto stub = v1::Registration::NewStub(peers_);

  std::mutex mutex;  // guards next, done() and failure
  std::size_t next = 0;
  std::exception_ptr failure;
  OutstandingCalls calls;
  std::atomic<bool> stop{false};
  std::atomic<int> running{0};  // workers not yet finished

  // One pair, on a peer if one answers, else here.
  auto register_one = [&](std::size_t k) {
    const auto start = Clock::now();
    double backoff = options_.first_backoff_s;
    int waits = 0;
    // First the digests only: a peer that holds both scans from earlier pairs needs nothing else (and has their
    // voxels and keypoints); one that does not answers NOT_FOUND, and the points follow at once.
    v1::RegisterPairRequest request;
    auto with = [&](const std::vector<v1::PairCloud>& sent_clouds) {
      *request.mutable_source() = sent_clouds[pairs[k].first];
      *request.mutable_target() = sent_clouds[pairs[k].second];
    };
    *request.mutable_params() = sent;
    with(clouds);
    const bool fits = request.ByteSizeLong() <= options_.max_pair_bytes;
    with(digests);
    bool with_points = false;
    for (int failed = 0; fits && failed < options_.attempts && !stop;) {
      grpc::ClientContext context;
      context.set_deadline(std::chrono::system_clock::now() +
                           std::chrono::duration_cast<std::chrono::system_clock::duration>(
                               std::chrono::duration<double>(options_.call_timeout_s)));
      context.AddMetadata("x-request-id", caller_.request_id);
      if (!caller_.auth_token.empty()) context.AddMetadata("authorization", "Bearer " + caller_.auth_token);
      v1::RegisterPairResponse reply;
      calls.add(&context);
      grpc::Status status = stub->RegisterPair(&context, request, &reply);
      calls.remove(&context);
      if (status.ok())
        if (const std::string problem = reply_problem(reply, scans[pairs[k].first].cloud().size(),
                                                      scans[pairs[k].second].cloud().size());
            !problem.empty())
          status = {grpc::StatusCode::INTERNAL, "the peer's reply is unusable: " + problem};
      const std::string peer = context.peer().empty() ? "none" : context.peer();
      metrics_.peer_pair_sent(peer, request.ByteSizeLong());
      if (status.error_code() == grpc::StatusCode::NOT_FOUND && !with_points) {
        with_points = true;
        with(clouds);
        continue;
      }
      if (status.ok() || is_pair_outcome(status.error_code())) {
        PairOutcome outcome;
        if (status.ok())
          outcome.result = api::result_from_proto(reply.result());
        else
          outcome.error = Error(status.error_code() == grpc::StatusCode::FAILED_PRECONDITION ? ErrorCode::kFailedPrecondition
                                                                                              : ErrorCode::kInvalidArgument,
                                status.error_message());
        outcome.seconds = std::chrono::duration<double>(Clock::now() - start).count();
        ++placement_.on_peers;
        return outcome;
      }
      if (stop) break;
      metrics_.peer_pair_retried(peer, status_code_name(status.error_code()));
      // Backpressure is no failure, but a pair no peer ever takes (one over a peer's message limit, say) must
      // not wait forever: kMaxBackpressureWaits waits count as one failure.
      if (status.error_code() != grpc::StatusCode::RESOURCE_EXHAUSTED || ++waits % kMaxBackpressureWaits == 0) ++failed;
      ++placement_.retried;
      for (const auto until = Clock::now() + std::chrono::duration<double>(backoff); !stop && Clock::now() < until;)
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      backoff = std::min(2.0 * backoff, options_.max_backoff_s);
    }
    check(cancel);
    ++placement_.local;
    metrics_.peer_pair_failed(fits ? "peers_failed" : "too_large");
    return register_pair(scans[pairs[k].first], scans[pairs[k].second], params, cancel);
  };

  auto worker = [&] {
    struct Exit {
      std::atomic<int>& running;
      ~Exit() { --running; }
    } exit{running};
    for (;;) {
      std::size_t k;
      {
        const std::lock_guard lock(mutex);
        if (stop || next >= pairs.size()) return;
        k = next++;
      }
      try {
        PairOutcome outcome = register_one(k);
        const std::lock_guard lock(mutex);
        if (!stop) done(k, std::move(outcome));
      } catch (...) {
        const std::lock_guard lock(mutex);
        if (!failure) failure = std::current_exception();
        stop = true;
        calls.cancel_all();
        return;
      }
    }
  };
  std::vector<std::thread> workers;
  const int count = std::max(1, std::min<int>(options_.in_flight, static_cast<int>(pairs.size())));
  running = count;
  for (int w = 0; w < count; ++w) workers.emplace_back(worker);
  // The coordinator's cancellation or deadline reaches the calls in flight within 50 ms.
  while (running > 0) {
    if (cancel && (cancel->cancelled() || cancel->deadline_passed())) {
      stop = true;
      calls.cancel_all();
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  for (std::thread& t : workers) t.join();
  if (failure) std::rethrow_exception(failure);
  check(cancel);
}

}  // namespace k4reg::service
