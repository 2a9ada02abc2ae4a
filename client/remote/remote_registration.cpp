#include "remote/remote_registration.h"

#include <algorithm>
#include <chrono>
#include <thread>
#include <vector>

#include "commands/command_error.h"
#include "remote/local_file.h"
#include "reports/status_text.h"
#include "remote/upload_stream.h"

namespace k4reg::cli {
namespace {

using Stream = grpc::ClientReaderWriter<v1::RegisterStreamRequest, v1::RegisterStreamResponse>;

constexpr double kFirstBackoff_s = 1.0;       // gRPC's own reconnect backoff starts at 1 s
constexpr double kMaxBackoff_s = 16.0;

class Attempt {
 public:
  Attempt(v1::Registration::Stub& stub, grpc::ClientContext& context, RegistrationObserver& observer)
      : context_(context), observer_(observer), stream_(stub.RegisterStream(&context)) {}

  // The call's status; `response` is set when it is OK.
  grpc::Status run(const v1::UploadHeader& header, const std::vector<LocalFile>& uploads,
                   const std::vector<v1::CloudRole>& roles, v1::RegisterResponse& response) {
    v1::RegisterStreamRequest first;
    *first.mutable_header() = header;
    upload_files(
        *stream_, context_, first, uploads,
        [&roles](std::size_t i, const std::string& piece) {
          v1::RegisterStreamRequest chunk;
          chunk.mutable_chunk()->set_role(roles[i]);
          chunk.mutable_chunk()->set_data(piece);
          return chunk;
        },
        [this](std::uint64_t sent, std::uint64_t total) { observer_.on_upload(sent, total); });
    return finish(response);
  }

 private:
  grpc::Status finish(v1::RegisterResponse& response) {
    for (v1::RegisterStreamResponse event; stream_->Read(&event);) {
      if (event.has_result())
        response = std::move(*event.mutable_result());
      else
        observer_.on_event(event);
    }
    return stream_->Finish();
  }

  grpc::ClientContext& context_;
  RegistrationObserver& observer_;
  std::unique_ptr<Stream> stream_;
};

}  // namespace

v1::RegisterResponse register_remote(const std::shared_ptr<grpc::Channel>& channel, const ConnectionOptions& connection,
                                     const RemoteRegistration& job, const CallPolicy& policy,
                                     RegistrationObserver& observer) {
  v1::UploadHeader header;
  *header.mutable_params() = job.params;
  header.set_preview_points(job.preview_points);
  std::vector<LocalFile> uploads;
  std::vector<v1::CloudRole> roles;
  if (job.by_reference) {
    header.mutable_source()->set_path(job.source);
    header.mutable_target()->set_path(job.target);
  } else {
    // Both files are checked before connecting: a typo costs no upload.
    uploads = {describe_local_file(job.source), describe_local_file(job.target)};
    roles = {v1::CLOUD_ROLE_SOURCE, v1::CLOUD_ROLE_TARGET};
    *header.mutable_source()->mutable_upload() = uploads[0].description;
    *header.mutable_target()->mutable_upload() = uploads[1].description;
  }

  const auto deadline =
      policy.deadline_s > 0 ? deadline_after(policy.deadline_s) : std::chrono::system_clock::time_point::max();
  auto stub = v1::Registration::NewStub(channel);
  const int attempts = 1 + std::max(0, policy.retries);
  for (int attempt = 1;; ++attempt) {
    grpc::ClientContext context;
    add_call_metadata(context, connection, policy.request_id);
    if (policy.deadline_s > 0) context.set_deadline(deadline);
    v1::RegisterResponse response;
    const grpc::Status status = Attempt(*stub, context, observer).run(header, uploads, roles, response);
    if (status.ok()) {
      if (!response.has_result()) throw CommandError("INTERNAL: the server ended the call without a result");
      return response;
    }
    const std::string failure = describe_failure(status, *channel, connection.server);
    const double backoff_s = std::min(kFirstBackoff_s * (1 << std::min(attempt - 1, 8)), kMaxBackoff_s);
    const auto resume = deadline_after(backoff_s);
    if (status.error_code() != grpc::StatusCode::UNAVAILABLE || attempt == attempts || resume >= deadline)
      throw CommandError(failure);
    observer.on_retry(status_code_name(status.error_code()), backoff_s, attempt + 1, attempts);
    std::this_thread::sleep_until(resume);
  }
}

}  // namespace k4reg::cli
