// RegisterStream (bidirectional): header, then chunks spooled to files (size and CRC-32C checked), then
// the job; progress events and the result go back on the same call (upload_stream_reactor.h).
#pragma once

#include "rpc/upload_stream_reactor.h"

namespace k4reg::service {

class StreamReactor final : public UploadStreamReactor<v1::RegisterStreamRequest, v1::RegisterStreamResponse> {
 public:
  StreamReactor(ServiceContext& service, grpc::CallbackServerContext* context);

 private:
  void on_header(const v1::RegisterStreamRequest& request) override;
  void on_chunk(const v1::RegisterStreamRequest& request) override;
  void execute(Job& job) override;

  PairJob pair_;
};

}  // namespace k4reg::service
