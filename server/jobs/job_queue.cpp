#include "jobs/job_queue.h"

#include <algorithm>

namespace k4reg::service {

JobQueue::JobQueue(std::size_t workers, std::size_t capacity) : capacity_(capacity) {
  workers_.reserve(workers);
  for (std::size_t i = 0; i < workers; ++i) workers_.emplace_back([this] { work(); });
}

JobQueue::~JobQueue() { stop(); }

JobQueue::Submission JobQueue::submit(std::shared_ptr<Job> job) {
  Submission submission{Admission::kAccepted};
  {
    std::lock_guard lock(mutex_);
    if (!accepting_ || stopping_) return {Admission::kDraining};
    if (waiting_.size() >= capacity_) return {Admission::kQueueFull};
    submission.position = waiting_.size();
    waiting_.push_back(std::move(job));
  }
  has_work_.notify_one();
  notify_change();
  return submission;
}

bool JobQueue::withdraw(const Job* job) {
  {
    std::lock_guard lock(mutex_);
    const auto it = std::find_if(waiting_.begin(), waiting_.end(), [&](const auto& j) { return j.get() == job; });
    if (it == waiting_.end()) return false;
    waiting_.erase(it);
  }
  idle_.notify_all();
  notify_change();
  return true;
}

void JobQueue::stop_accepting() {
  std::lock_guard lock(mutex_);
  accepting_ = false;
}

bool JobQueue::accepting() const {
  std::lock_guard lock(mutex_);
  return accepting_ && !stopping_;
}

void JobQueue::cancel_all() {
  std::lock_guard lock(mutex_);
  for (const auto& job : waiting_) job->token().cancel();
  for (const auto& job : running_) job->token().cancel();
}

bool JobQueue::wait_idle(std::chrono::steady_clock::time_point deadline) {
  std::unique_lock lock(mutex_);
  return idle_.wait_until(lock, deadline, [this] { return waiting_.empty() && running_.empty(); });
}

void JobQueue::stop() {
  {
    std::lock_guard lock(mutex_);
    if (stopping_) return;
    stopping_ = true;
    // Cancelled waiting jobs still run (briefly) so that each one ends its RPC.
    for (const auto& job : waiting_) job->token().cancel();
  }
  has_work_.notify_all();
  for (std::thread& worker : workers_) worker.join();
}

bool JobQueue::full() const {
  std::lock_guard lock(mutex_);
  return waiting_.size() >= capacity_;
}

std::size_t JobQueue::waiting() const {
  std::lock_guard lock(mutex_);
  return waiting_.size();
}

std::size_t JobQueue::running() const {
  std::lock_guard lock(mutex_);
  return running_.size();
}

void JobQueue::work() {
  for (;;) {
    std::shared_ptr<Job> job;
    {
      std::unique_lock lock(mutex_);
      has_work_.wait(lock, [this] { return stopping_ || !waiting_.empty(); });
      if (waiting_.empty()) return;  // stopping and nothing left
      job = std::move(waiting_.front());
      waiting_.pop_front();
      running_.push_back(job);
    }
    notify_change();
    job->run();
    {
      std::lock_guard lock(mutex_);
      running_.erase(std::find(running_.begin(), running_.end(), job));
    }
    idle_.notify_all();
  }
}

void JobQueue::set_on_change(std::function<void()> on_change) {
  std::lock_guard lock(mutex_);
  on_change_ = std::move(on_change);
}

void JobQueue::notify_change() {
  std::function<void()> on_change;
  {
    std::lock_guard lock(mutex_);
    on_change = on_change_;
  }
  if (on_change) on_change();
}

}  // namespace k4reg::service
