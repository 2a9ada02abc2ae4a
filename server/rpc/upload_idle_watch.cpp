#include "rpc/upload_idle_watch.h"

#include <algorithm>

namespace k4reg::service {

UploadIdleWatch::UploadIdleWatch(double timeout_s) : timeout_s_(timeout_s), thread_([this] { run(); }) {}

UploadIdleWatch::~UploadIdleWatch() {
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  stop_.notify_all();
  thread_.join();
}

void UploadIdleWatch::watch(Call& call) {
  call.touch();
  const std::lock_guard lock(mutex_);
  calls_.insert(&call);
}

void UploadIdleWatch::unwatch(Call& call) {
  const std::lock_guard lock(mutex_);
  calls_.erase(&call);
}

void UploadIdleWatch::run() {
  const auto timeout = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout_s_));
  // A call is cancelled between the timeout and a quarter more (at most a second more).
  const auto period = std::min<Clock::duration>(timeout / 4, std::chrono::seconds(1));
  std::unique_lock lock(mutex_);
  while (!stop_.wait_for(lock, period, [this] { return stopping_; })) {
    const Clock::rep oldest = (Clock::now() - timeout).time_since_epoch().count();
    // Under the lock: unwatch() comes before a call's context goes, so none is cancelled after it went.
    for (Call* call : calls_)
      if (call->last_message < oldest && !call->timed_out.exchange(true)) call->context->TryCancel();
  }
}

}  // namespace k4reg::service
