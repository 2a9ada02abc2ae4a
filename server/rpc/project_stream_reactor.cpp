#include "rpc/project_stream_reactor.h"

#include <fmt/format.h>

#include "rpc/project_reactor.h"

namespace k4reg::service {

ProjectStreamReactor::ProjectStreamReactor(ServiceContext& service, grpc::CallbackServerContext* context)
    : UploadStreamReactor(service, context) {
  begin("/k4reg.v1.Registration/RegisterProjectStream");
}

void ProjectStreamReactor::on_header(const v1::RegisterProjectStreamRequest& request) {
  const v1::ProjectUploadHeader& header = request.header();
  service_.limits.check_project_scans(static_cast<std::size_t>(header.scans_size()));  // before any spool file
  std::vector<CloudSource> scans;
  for (int i = 0; i < header.scans_size(); ++i) scans.push_back(uploads_.add(header.scans(i), fmt::format("scan {}", i)));
  project_ = make_project_job(std::move(scans), header.params(), header.preview_points());
}

void ProjectStreamReactor::on_chunk(const v1::RegisterProjectStreamRequest& request) {
  uploads_.append(request.chunk().scan(), request.chunk().data());
}

void ProjectStreamReactor::execute(Job& job) {
  finish(run_project_call(service_, job, project_, clock_, record_, stage_listener(clock_), poster()));
}

}  // namespace k4reg::service
