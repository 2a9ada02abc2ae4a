// RegisterStream (bidirectional): header, then chunks spooled to files (size and CRC-32C checked), then
// the job; progress events and the result go back on the same call.
//
// Threads: reads and their reactions run on gRPC threads (appending a <= 1 MiB chunk to a spool file is
// quick); the job runs on a worker, which posts events. Writes are serialised through an outbox because
// gRPC allows one write in flight; Finish waits until the outbox is empty.
#pragma once

#include <grpcpp/support/server_callback.h>

#include <array>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>

#include "request_log.h"
#include "service_context.h"

namespace k4reg::service {

class StreamReactor final : public grpc::ServerBidiReactor<v1::RegisterStreamRequest, v1::RegisterStreamResponse> {
 public:
  StreamReactor(ServiceContext& service, grpc::CallbackServerContext* context);

  void OnReadDone(bool ok) override;
  void OnWriteDone(bool ok) override;
  void OnCancel() override;
  void OnDone() override;

 private:
  struct Upload {
    std::unique_ptr<SpoolFile> file;  // null: this cloud is a path reference
    std::uint64_t size_bytes = 0;
    std::uint32_t crc32c = 0;
    bool complete = false;
  };

  void on_header(const v1::UploadHeader& header);
  void on_chunk(const v1::UploadChunk& chunk);
  CloudSource prepare(const v1::StreamCloud& cloud, const char* role, Upload& upload);
  void verify(Upload& upload, const CloudSource& source, const char* role);
  bool uploads_complete() const;
  void read_next_or_start_job();
  void execute(Job& job);  // on a worker

  void post(v1::RegisterStreamResponse message);  // any thread
  void post_locked(v1::RegisterStreamResponse message);  // with mutex_ held
  void post_stage(const std::string& stage, v1::StageEvent::Phase phase, double fraction);
  void finish(const grpc::Status& status);  // any thread; once the outbox is empty

  ServiceContext& service_;
  grpc::CallbackServerContext* context_;
  RequestRecord record_;
  CallClock clock_;
  v1::RegisterStreamRequest request_;
  bool header_seen_ = false;
  RegistrationParams params_;
  CloudSource source_, target_;
  std::array<Upload, 2> uploads_;  // source, target

  std::mutex mutex_;  // guards everything below
  std::shared_ptr<Job> job_;
  bool cancelled_ = false;
  std::deque<v1::RegisterStreamResponse> outbox_;  // front is in flight while writing_
  bool writing_ = false, write_failed_ = false, finished_ = false;
  std::optional<grpc::Status> final_status_;
  CallClock::Clock::time_point last_progress_;
};

}  // namespace k4reg::service
