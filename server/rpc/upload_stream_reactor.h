// The server side of a streaming upload call (RegisterStream, RegisterProjectStream): a header naming the
// clouds (paths on the server or uploads), then the uploads in chunks, spooled and checked (stream_uploads.h);
// once every declared byte has arrived the job is queued, and its events go back on the same call.
//
// A call that sends no message for --upload-idle-timeout-s before its uploads are complete is cancelled
// (upload_idle_watch.h) and ends DEADLINE_EXCEEDED naming the flag.
//
// Threads: reads and their reactions run on gRPC threads (appending a <= 1 MiB chunk to a spool file is
// quick); the job runs on a worker, which posts events through the outbox (job_stream_reactor.h).
#pragma once

#include <grpcpp/support/server_callback.h>

#include <fmt/format.h>

#include "rpc/job_stream_reactor.h"
#include "k4reg/util/error.h"
#include "observability/request_log.h"
#include "service_context.h"
#include "api/status_mapping.h"
#include "rpc/stream_uploads.h"
#include "rpc/upload_idle_watch.h"

namespace k4reg::service {

template <class Request, class Event>
class UploadStreamReactor : public JobStreamReactor<grpc::ServerBidiReactor<Request, Event>, Event> {
  using Base = JobStreamReactor<grpc::ServerBidiReactor<Request, Event>, Event>;

 public:
  UploadStreamReactor(ServiceContext& service, grpc::CallbackServerContext* context)
      : Base(service), uploads_(service), context_(context) {}

  void OnReadDone(bool ok) override {
    if (!ok) {
      // The client closed its side (or the call broke, or sent nothing for too long) before every declared byte
      // arrived.
      if (idle_.timed_out)
        this->finish({grpc::StatusCode::DEADLINE_EXCEEDED,
                      fmt::format("no upload message for {:g} s (--upload-idle-timeout-s)",
                                  this->service_.idle_uploads.timeout_s())});
      else
        this->finish(context_->IsCancelled() ? grpc::Status::CANCELLED
                                             : grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                                                            header_seen_ ? "stream ended before the uploads were complete"
                                                                         : "stream ended before the header"));
      return;
    }
    idle_.touch();
    try {
      if (!header_seen_) {
        if (!request_.has_header()) fail(ErrorCode::kInvalidArgument, "the first message must be the header");
        header_seen_ = true;
        clock_.upload_start = CallClock::Clock::now();
        on_header(request_);
        record_.upload_bytes = uploads_.declared_bytes();
      } else {
        if (!request_.has_chunk()) fail(ErrorCode::kInvalidArgument, "only chunks may follow the header");
        on_chunk(request_);
      }
    } catch (...) {
      this->finish(status_from_current_exception());
      return;
    }
    if (!uploads_.complete()) {
      this->StartRead(&request_);
      return;
    }
    clock_.upload_end = CallClock::Clock::now();
    this->service_.idle_uploads.unwatch(idle_);  // waiting for a worker is no idling
    this->start_job(*context_, clock_, [this](Job& job) { execute(job); });
  }

  void OnDone() override {
    this->service_.idle_uploads.unwatch(idle_);
    delete this;
  }

 protected:
  // The last step of the derived reactor's constructor: reads may call back at once, on another thread.
  void begin(const char* method) {
    record_ = open_request(*context_, method);
    if (const grpc::Status status = this->service_.admit(*context_); !status.ok()) {
      this->finish(status);
      return;
    }
    idle_.context = context_;
    this->service_.idle_uploads.watch(idle_);
    this->StartRead(&request_);
  }

  // On a gRPC thread; throw k4reg::Error to refuse. on_header adds the clouds to uploads_.
  virtual void on_header(const Request& request) = 0;
  virtual void on_chunk(const Request& request) = 0;
  // On a worker: runs the job, posts its result and finishes the call.
  virtual void execute(Job& job) = 0;

  StreamUploads uploads_;
  RequestRecord record_;
  CallClock clock_;

 private:
  void on_finishing(const grpc::Status& status) override {
    // Nothing reads the spool files any more (no job and no read in flight at any call of finish), and the
    // client should not see its status before they are gone.
    uploads_.clear();
    record_.code = status.error_code();
    record_.error = status.error_message();
    this->service_.end_request(record_);  // before the status leaves: a client that got its answer finds the log line
  }

  grpc::CallbackServerContext* context_;
  Request request_;
  bool header_seen_ = false;
  UploadIdleWatch::Call idle_;
};

}  // namespace k4reg::service
