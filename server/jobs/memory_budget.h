// Admission by memory: the running jobs together may hold at most the configured budget.
//
// A job's need is estimated from its input points, kBytesPerPoint each (source + target). Measured peak RSS
// of `k4reg align --threads 1` minus that of a tiny run: bunny pair at min_scale_m 0.001 (80 k points)
// ~60 B/point; a 2 M-point synthetic terrain at min_scale_m 0.05 ~40 B/point. Not covered: the 4PCS tables
// grow with the keypoint count, not the point count (the same terrain at 0.01 m gave 20 k keypoints and a
// 5 GB peak), and the mapped input file and inline request bytes (page cache / gRPC buffers).
#pragma once

#include <condition_variable>
#include <cstddef>
#include <mutex>
#include <optional>

#include "k4reg/util/cancellation.h"

namespace k4reg::service {

inline constexpr std::size_t kBytesPerPoint = 60;

class MemoryBudget {
 public:
  explicit MemoryBudget(std::size_t budget_bytes) : budget_(budget_bytes) {}

  // Returns what it reserved to the budget when dropped.
  class Reservation {
   public:
    Reservation(MemoryBudget& budget, std::size_t bytes) : budget_(&budget), bytes_(bytes) {}
    Reservation(Reservation&& other) noexcept : budget_(other.budget_), bytes_(other.bytes_) { other.budget_ = nullptr; }
    Reservation(const Reservation&) = delete;
    Reservation& operator=(const Reservation&) = delete;
    Reservation& operator=(Reservation&&) = delete;
    ~Reservation();

   private:
    MemoryBudget* budget_;
    std::size_t bytes_;
  };

  // Waits until `bytes` fit beside the running jobs (they finish, so the wait ends). Throws
  // k4reg::Error: kResourceExhausted if `bytes` exceed the whole budget, kCancelled / kDeadlineExceeded
  // if the token fires while waiting.
  Reservation reserve(std::size_t bytes, const CancellationToken& token);
  // The same without waiting: nullopt when `bytes` do not fit now. For jobs whose waiting could close a cycle (a
  // peer's pair job, waited for by a project that holds memory on another replica).
  std::optional<Reservation> try_reserve(std::size_t bytes);

  std::size_t in_use() const;

 private:
  void release(std::size_t bytes);
  void check_within_budget(std::size_t bytes) const;  // throws kResourceExhausted

  const std::size_t budget_;
  mutable std::mutex mutex_;
  std::condition_variable freed_;
  std::size_t in_use_ = 0;
};

}  // namespace k4reg::service
