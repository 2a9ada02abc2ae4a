#include "jobs/memory_budget.h"

#include <chrono>
#include <string>

#include "k4reg/util/error.h"

namespace k4reg::service {

MemoryBudget::Reservation::~Reservation() {
  if (budget_) budget_->release(bytes_);
}

void MemoryBudget::check_within_budget(std::size_t bytes) const {
  constexpr std::size_t kMiB = 1 << 20;
  if (bytes > budget_)
    fail(ErrorCode::kResourceExhausted,
         "the job needs an estimated " + std::to_string((bytes + kMiB - 1) / kMiB) + " MiB (" +
             std::to_string(kBytesPerPoint) + " bytes per input point), more than the memory budget of " +
             std::to_string(budget_ / kMiB) + " MiB (--memory-budget-mb)");
}

MemoryBudget::Reservation MemoryBudget::reserve(std::size_t bytes, const CancellationToken& token) {
  check_within_budget(bytes);
  std::unique_lock lock(mutex_);
  // Poll the token: cancellation has no way to notify this condition variable.
  while (in_use_ + bytes > budget_) {
    freed_.wait_for(lock, std::chrono::milliseconds(20));
    token.throw_if_stopped();
  }
  in_use_ += bytes;
  return Reservation(*this, bytes);
}

std::optional<MemoryBudget::Reservation> MemoryBudget::try_reserve(std::size_t bytes) {
  check_within_budget(bytes);
  std::lock_guard lock(mutex_);
  if (in_use_ + bytes > budget_) return std::nullopt;
  in_use_ += bytes;
  return Reservation(*this, bytes);
}

std::size_t MemoryBudget::in_use() const {
  std::lock_guard lock(mutex_);
  return in_use_;
}

void MemoryBudget::release(std::size_t bytes) {
  {
    std::lock_guard lock(mutex_);
    in_use_ -= bytes;
  }
  freed_.notify_all();
}

}  // namespace k4reg::service
