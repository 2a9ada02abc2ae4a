#include "remote/load_runner.h"

#include <sys/resource.h>

#include <algorithm>
#include <condition_variable>
#include <mutex>
#include <thread>

#include "reports/status_text.h"

namespace k4reg::cli {
namespace {

using Clock = std::chrono::steady_clock;

double cpu_seconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  auto seconds = [](const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec); };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

// round_robin connects to every address at once but reports READY with the first, and it only picks READY
// addresses: a burst sent right then lands on one replica, whose queue then holds the backlog for the whole
// run (measured: 19/10/11 calls and a 7.6 s p99 queue wait over three replicas, 13/14/13 and no backlog with
// the pause). The others are a loopback or LAN handshake behind, so a short pause lets them catch up.
constexpr auto kConnectSettle = std::chrono::milliseconds(200);

// Connection set-up should not count as the first calls' latency. Returns early when the target cannot be
// reached (TRANSIENT_FAILURE): the calls then fail and are counted by status code.
void wait_for_connection(grpc::Channel& channel, std::chrono::system_clock::time_point deadline) {
  grpc_connectivity_state state = channel.GetState(true);
  while (state != GRPC_CHANNEL_READY && state != GRPC_CHANNEL_TRANSIENT_FAILURE) {
    if (!channel.WaitForStateChange(state, deadline)) return;
    state = channel.GetState(true);
  }
  if (state == GRPC_CHANNEL_READY) std::this_thread::sleep_for(kConnectSettle);
}

// Calls go through gRPC's callback API: completions arrive on gRPC's threads, so the open loop needs no thread
// per call in flight and the closed loop starts the next call right from the completion.
class LoadRun {
 public:
  LoadRun(const std::shared_ptr<grpc::Channel>& channel, const ConnectionOptions& connection, const LoadPlan& plan)
      : channel_(channel), stub_(v1::Registration::NewStub(channel)), connection_(connection), plan_(plan) {}

  LoadOutcome run() {
    wait_for_connection(*channel_, deadline_after(std::min(plan_.deadline_s, 10.0)));
    const double cpu_start = cpu_seconds();
    start_ = Clock::now();
    end_ = plan_.duration_s > 0
               ? start_ + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(plan_.duration_s))
               : Clock::time_point::max();
    if (plan_.rate > 0) {
      dispatch_on_schedule();
    } else {
      for (int k = 0; k < plan_.concurrency; ++k) launch_next(Clock::now());
    }
    std::unique_lock lock(mutex_);
    done_.wait(lock, [this] { return in_flight_ == 0; });
    outcome_.wall_s = std::chrono::duration<double>(last_completion_ - start_).count();
    outcome_.cpu_s = cpu_seconds() - cpu_start;
    return std::move(outcome_);
  }

 private:
  struct Call {
    grpc::ClientContext context;
    v1::RegisterResponse response;
    Clock::time_point scheduled;
  };

  // Takes the next request index if the plan allows another call that starts at `now`.
  bool claim(Clock::time_point now, std::size_t& index) {
    std::lock_guard lock(mutex_);
    if (plan_.total > 0 ? issued_ >= plan_.total : now >= end_) return false;
    index = issued_++;
    ++in_flight_;
    return true;
  }

  void launch_next(Clock::time_point scheduled) {
    std::size_t index = 0;
    if (claim(scheduled, index)) launch(index, scheduled);
  }

  void launch(std::size_t index, Clock::time_point scheduled) {
    auto* call = new Call;  // owned by the call until its completion callback
    call->scheduled = scheduled;
    add_call_metadata(call->context, connection_, "");  // no request id: the server generates one per call
    call->context.set_deadline(deadline_after(plan_.deadline_s));
    stub_->async()->Register(&call->context, &plan_.requests[index % plan_.requests.size()], &call->response,
                             [this, call](grpc::Status status) { complete(std::unique_ptr<Call>(call), status); });
  }

  void complete(std::unique_ptr<Call> call, const grpc::Status& status) {
    const Clock::time_point now = Clock::now();
    CallRecord record;
    record.code = status.error_code();
    record.latency_s = std::chrono::duration<double>(now - call->scheduled).count();
    if (status.ok()) {
      record.timings = call->response.timings();
      record.server_id = call->response.server().server_id();
    }
    const std::string failure = status.ok() ? std::string() : describe_failure(status, *channel_, connection_.server);
    call.reset();
    // The next call is in flight before this one leaves, so run() cannot see zero calls in flight too early.
    if (plan_.rate <= 0) launch_next(now);
    std::lock_guard lock(mutex_);
    outcome_.calls.push_back(std::move(record));
    if (outcome_.first_failure.empty()) outcome_.first_failure = failure;
    last_completion_ = std::max(last_completion_, now);
    if (--in_flight_ == 0) done_.notify_all();
  }

  void dispatch_on_schedule() {
    // Counts as one call in flight until the schedule is over, so run() waits for the dispatcher too.
    {
      std::lock_guard lock(mutex_);
      ++in_flight_;
    }
    const auto interval = std::chrono::duration<double>(1.0 / plan_.rate);
    for (std::size_t k = 0;; ++k) {
      const Clock::time_point scheduled = start_ + std::chrono::duration_cast<Clock::duration>(interval * k);
      std::size_t index = 0;
      if (!claim(scheduled, index)) break;
      std::this_thread::sleep_until(scheduled);
      launch(index, scheduled);
    }
    std::lock_guard lock(mutex_);
    last_completion_ = std::max(last_completion_, Clock::now());
    if (--in_flight_ == 0) done_.notify_all();
  }

  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::Registration::Stub> stub_;
  const ConnectionOptions& connection_;
  const LoadPlan& plan_;
  Clock::time_point start_, end_, last_completion_;
  std::mutex mutex_;
  std::condition_variable done_;
  std::size_t issued_ = 0, in_flight_ = 0;
  LoadOutcome outcome_;
};

}  // namespace

LoadOutcome run_load(const std::shared_ptr<grpc::Channel>& channel, const ConnectionOptions& connection,
                     const LoadPlan& plan) {
  return LoadRun(channel, connection, plan).run();
}

}  // namespace k4reg::cli
