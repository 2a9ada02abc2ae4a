// The service's CPU work runs here, never on gRPC threads: a fixed pool of workers fed by a bounded
// FIFO queue. A full queue refuses at once (the caller answers RESOURCE_EXHAUSTED) instead of letting
// latency grow without bound; a draining queue refuses everything new (UNAVAILABLE).
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "k4reg/util/cancellation.h"

namespace k4reg::service {

// One unit of work. The body must end its RPC itself, also when the token has already fired (it then
// returns quickly with CANCELLED / DEADLINE_EXCEEDED).
class Job {
 public:
  explicit Job(std::function<void(Job&)> body) : body_(std::move(body)) {}
  void run() { body_(*this); }
  CancellationToken& token() { return token_; }

 private:
  std::function<void(Job&)> body_;
  CancellationToken token_;
};

class JobQueue {
 public:
  enum class Admission { kAccepted, kQueueFull, kDraining };
  struct Submission {
    Admission admission;
    std::size_t position = 0;  // jobs waiting ahead of this one
  };

  // `capacity` counts waiting jobs; the `workers` running ones come on top.
  JobQueue(std::size_t workers, std::size_t capacity);
  ~JobQueue();  // stop()

  Submission submit(std::shared_ptr<Job> job);
  // Takes a job out of the queue if no worker has picked it up yet; true = it will never run, so the
  // caller ends its RPC itself.
  bool withdraw(const Job* job);

  // After this, submit() answers kDraining.
  void stop_accepting();
  bool accepting() const;
  // Fires the token of every waiting and running job.
  void cancel_all();
  // True once no job waits or runs; false if the deadline came first.
  bool wait_idle(std::chrono::steady_clock::time_point deadline);
  // Ends the workers after the jobs they hold; waiting jobs are cancelled first. Idempotent.
  void stop();

  bool full() const;
  std::size_t waiting() const;
  std::size_t running() const;
  std::size_t capacity() const { return capacity_; }
  std::size_t workers() const { return workers_.size(); }

  // Called (without the queue's lock held) whenever the number of waiting jobs changes, e.g. to publish
  // readiness. May be set while the queue is in use (the health service exists only once gRPC runs).
  void set_on_change(std::function<void()> on_change);

 private:
  void work();
  void notify_change();

  const std::size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable has_work_, idle_;
  std::deque<std::shared_ptr<Job>> waiting_;
  std::vector<std::shared_ptr<Job>> running_;
  bool accepting_ = true, stopping_ = false;
  std::function<void()> on_change_;
  std::vector<std::thread> workers_;
};

}  // namespace k4reg::service
