// The server side of a streaming call that runs one job and streams its events (RegisterStream,
// RegisterProject): the job is queued with a "queued" event and cancelled with the call; its events come
// from a worker thread, and since gRPC allows one write in flight they wait in an outbox and go out in
// order, the final status once the outbox is empty. Progress events are rate-limited; starts and ends of
// stages always go out.
#pragma once

#include <grpcpp/support/server_callback.h>

#include <chrono>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "k4reg/v1/registration.pb.h"
#include "service_context.h"

namespace k4reg::service {

template <class Base, class Message>
class JobStreamReactor : public Base {
 public:
  explicit JobStreamReactor(ServiceContext& service) : service_(service) {}

  // The client went away or its deadline passed: the job stops (or, still queued, never runs).
  void OnCancel() override {
    std::shared_ptr<Job> job;
    {
      std::lock_guard lock(mutex_);
      cancelled_ = true;
      job = job_;
    }
    if (!job) return;  // no job yet: whatever the call waits for fails and finishes it
    job->token().cancel();
    if (service_.withdraw(job.get())) finish({grpc::StatusCode::CANCELLED, "cancelled while queued"});
  }

  void OnWriteDone(bool ok) override {
    grpc::Status status;
    {
      std::lock_guard lock(mutex_);
      outbox_.pop_front();
      writing_ = false;
      if (!ok) {  // the call is broken (cancelled); nothing more will be delivered
        write_failed_ = true;
        outbox_.clear();
      }
      if (!outbox_.empty()) {
        writing_ = true;
        this->StartWrite(&outbox_.front());
        return;
      }
      if (!final_status_ || finished_) return;
      finished_ = true;
      status = *final_status_;
    }
    this->Finish(status);
  }

 protected:
  // Queues the job that `run` does (with the call's deadline) and posts the queued event, or finishes the
  // call with the refusal.
  void start_job(const grpc::ServerContextBase& context, CallClock& clock, std::function<void(Job&)> run) {
    auto job = std::make_shared<Job>(std::move(run));
    apply_deadline(context, job->token());
    grpc::Status status;
    {
      // Held across submit(): a worker that picks the job up at once posts its first event only after the
      // queued event.
      std::lock_guard lock(mutex_);
      if (cancelled_) job->token().cancel();  // OnCancel came before there was a job to cancel
      job_ = job;
      clock.enqueued = CallClock::Clock::now();
      std::size_t position = 0;
      status = service_.submit(job, position);
      if (status.ok()) {
        Message queued;
        queued.mutable_queued()->set_position(static_cast<std::uint32_t>(position));
        post_locked(std::move(queued));
      }
    }
    if (!status.ok()) finish(status);
  }

  // Any thread. Dropped once the call is finishing or broken.
  void post(Message message) {
    std::lock_guard lock(mutex_);
    post_locked(std::move(message));
  }
  // With mutex_ held.
  void post_locked(Message message) {
    if (write_failed_ || final_status_) return;
    outbox_.push_back(std::move(message));
    if (writing_) return;
    writing_ = true;
    this->StartWrite(&outbox_.front());  // a deque keeps the front in place while later messages are added
  }
  // The job's stage events (both messages carry one as `stage`), timed from the job's start; progress events
  // at most every 100 ms. Any thread.
  std::function<void(const std::string&, v1::StageEvent::Phase, double)> stage_listener(const CallClock& clock) {
    return [this, &clock](const std::string& stage, v1::StageEvent::Phase phase, double fraction) {
      const auto now = CallClock::Clock::now();
      std::lock_guard lock(mutex_);
      if (phase == v1::StageEvent::PHASE_PROGRESS) {
        if (now - last_progress_ < std::chrono::milliseconds(100)) return;
        last_progress_ = now;
      }
      post_locked(make_stage_event<Message>(stage, phase, fraction, clock, now));
    };
  }
  // post() as a function for the job's other events.
  std::function<void(Message)> poster() {
    return [this](Message message) { post(std::move(message)); };
  }
  // Any thread; only the first call counts. The call ends with `status` once the outbox is empty.
  void finish(const grpc::Status& status) {
    {
      std::lock_guard lock(mutex_);
      if (final_status_) return;
      final_status_ = status;
      on_finishing(status);
      if (writing_) return;  // OnWriteDone finishes once the outbox is empty
      finished_ = true;
    }
    this->Finish(status);
  }
  // Called once, with mutex_ held, when the final status is set and before it leaves (access log, cleanup).
  virtual void on_finishing(const grpc::Status& status) = 0;

  ServiceContext& service_;
  std::mutex mutex_;  // guards the job, the outbox and what the derived reactor says

 private:
  std::shared_ptr<Job> job_;
  bool cancelled_ = false;
  std::deque<Message> outbox_;  // front is in flight while writing_
  bool writing_ = false, write_failed_ = false, finished_ = false;
  std::optional<grpc::Status> final_status_;
  std::chrono::steady_clock::time_point last_progress_;
};

}  // namespace k4reg::service
