// RegisterStream (bidirectional): header, then chunks spooled to files (size and CRC-32C checked), then
// the job; progress events and the result go back on the same call.
//
// Threads: reads and their reactions run on gRPC threads (appending a <= 1 MiB chunk to a spool file is
// quick); the job runs on a worker, which posts events through the outbox (job_stream_reactor.h).
#pragma once

#include <grpcpp/support/server_callback.h>

#include <array>
#include <memory>

#include "job_stream_reactor.h"
#include "request_log.h"
#include "service_context.h"

namespace k4reg::service {

class StreamReactor final
    : public JobStreamReactor<grpc::ServerBidiReactor<v1::RegisterStreamRequest, v1::RegisterStreamResponse>,
                              v1::RegisterStreamResponse> {
 public:
  StreamReactor(ServiceContext& service, grpc::CallbackServerContext* context);

  void OnReadDone(bool ok) override;
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

  void on_finishing(const grpc::Status& status) override;

  grpc::CallbackServerContext* context_;
  RequestRecord record_;
  CallClock clock_;
  v1::RegisterStreamRequest request_;
  bool header_seen_ = false;
  RegistrationParams params_;
  std::size_t preview_points_ = 0;
  CloudSource source_, target_;
  std::array<Upload, 2> uploads_;  // source, target
};

}  // namespace k4reg::service
