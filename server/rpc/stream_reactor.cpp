#include "rpc/stream_reactor.h"

#include "api/proto_convert.h"

namespace k4reg::service {

StreamReactor::StreamReactor(ServiceContext& service, grpc::CallbackServerContext* context)
    : UploadStreamReactor(service, context) {
  begin("/k4reg.v1.Registration/RegisterStream");
}

void StreamReactor::on_header(const v1::RegisterStreamRequest& request) {
  const v1::UploadHeader& header = request.header();
  pair_.params = params_from_proto(header.params());
  pair_.preview_points = preview_points_from_proto(header.preview_points());
  pair_.source = uploads_.add(header.source(), "source");
  pair_.target = uploads_.add(header.target(), "target");
}

void StreamReactor::on_chunk(const v1::RegisterStreamRequest& request) {
  const v1::UploadChunk& chunk = request.chunk();
  const bool is_source = chunk.role() == v1::CLOUD_ROLE_SOURCE;
  if (!is_source && chunk.role() != v1::CLOUD_ROLE_TARGET)
    fail(ErrorCode::kInvalidArgument, "chunk role must be CLOUD_ROLE_SOURCE or CLOUD_ROLE_TARGET");
  uploads_.append(is_source ? 0 : 1, chunk.data());
}

void StreamReactor::execute(Job& job) {
  v1::RegisterStreamResponse reply;
  const grpc::Status status =
      run_job(service_, job, pair_, stage_listener(clock_), clock_, record_, *reply.mutable_result());
  if (status.ok()) post(std::move(reply));
  finish(status);
}

}  // namespace k4reg::service
