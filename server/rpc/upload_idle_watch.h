// Ends upload calls that stop sending (--upload-idle-timeout-s): a client that declared uploads and then sends
// nothing would hold its spool files, a descriptor and a call as long as it likes. One thread looks at the watched
// calls a few times per timeout and cancels those that received no message for the timeout; the call then ends
// naming the flag (UploadStreamReactor).
#pragma once

#include <grpcpp/server_context.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <set>
#include <thread>

namespace k4reg::service {

class UploadIdleWatch {
 public:
  using Clock = std::chrono::steady_clock;

  // One watched call: its context and when its last message came.
  struct Call {
    grpc::ServerContextBase* context = nullptr;
    std::atomic<Clock::rep> last_message{0};
    std::atomic<bool> timed_out{false};  // set before the watch cancels the call
    void touch() { last_message = Clock::now().time_since_epoch().count(); }
  };

  explicit UploadIdleWatch(double timeout_s);
  ~UploadIdleWatch();
  UploadIdleWatch(const UploadIdleWatch&) = delete;
  UploadIdleWatch& operator=(const UploadIdleWatch&) = delete;

  double timeout_s() const { return timeout_s_; }
  // Watched from now (touched) until unwatch(), which must come before the call's context goes.
  void watch(Call& call);
  void unwatch(Call& call);

 private:
  void run();

  const double timeout_s_;
  std::mutex mutex_;
  std::condition_variable stop_;
  bool stopping_ = false;
  std::set<Call*> calls_;
  std::thread thread_;
};

}  // namespace k4reg::service
