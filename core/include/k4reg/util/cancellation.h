// Cooperative cancellation and progress reporting for long core calls. A token is shared between
// the caller (who cancels, e.g. on a client disconnect) and the worker (who polls it cheaply).
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <string>

namespace k4reg {

class CancellationToken {
 public:
  using Clock = std::chrono::steady_clock;

  // A token that also stops when `parent` (optional, must outlive it) does.
  explicit CancellationToken(const CancellationToken* parent = nullptr) : parent_(parent) {}

  void cancel() { cancelled_.store(true, std::memory_order_relaxed); }
  void set_deadline(Clock::time_point deadline) {
    deadline_ns_.store(deadline.time_since_epoch().count(), std::memory_order_relaxed);
  }
  bool cancelled() const { return cancelled_.load(std::memory_order_relaxed) || (parent_ && parent_->cancelled()); }
  bool deadline_passed() const {
    const auto d = deadline_ns_.load(std::memory_order_relaxed);
    return (d != 0 && Clock::now().time_since_epoch().count() >= d) || (parent_ && parent_->deadline_passed());
  }
  // Throws Error(kCancelled) or Error(kDeadlineExceeded). Call it every few milliseconds of work.
  void throw_if_stopped() const;

 private:
  const CancellationToken* parent_;
  std::atomic<bool> cancelled_{false};
  std::atomic<Clock::rep> deadline_ns_{0};
};

// Throws if the (optional) token has fired.
inline void check(const CancellationToken* token) {
  if (token) token->throw_if_stopped();
}

// Stage names are stable strings ("voxel_grid", "keypoints", "matching", "icp", ...); fraction in [0, 1].
using ProgressCallback = std::function<void(const std::string& stage, double fraction)>;

}  // namespace k4reg
