// RegisterProjectStream (bidirectional): a header naming every scan (a path on the server or an upload),
// then the uploads in chunks spooled to files (size and CRC-32C checked), then the project job, whose events
// and result go back on the same call as for RegisterProject (upload_stream_reactor.h).
#pragma once

#include "jobs/project_job.h"
#include "rpc/upload_stream_reactor.h"

namespace k4reg::service {

class ProjectStreamReactor final
    : public UploadStreamReactor<v1::RegisterProjectStreamRequest, v1::RegisterProjectEvent> {
 public:
  ProjectStreamReactor(ServiceContext& service, grpc::CallbackServerContext* context);

 private:
  void on_header(const v1::RegisterProjectStreamRequest& request) override;
  void on_chunk(const v1::RegisterProjectStreamRequest& request) override;
  void execute(Job& job) override;

  ProjectJob project_;
};

}  // namespace k4reg::service
