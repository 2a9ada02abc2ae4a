#include "stream_reactor.h"

#include <fmt/format.h>

#include "k4reg/util/error.h"
#include "proto_convert.h"
#include "status_mapping.h"

namespace k4reg::service {
namespace {

constexpr std::size_t kMaxChunkBytes = 1 << 20;

}  // namespace

StreamReactor::StreamReactor(ServiceContext& service, grpc::CallbackServerContext* context)
    : JobStreamReactor(service), context_(context) {
  record_ = open_request(*context, "/k4reg.v1.Registration/RegisterStream");
  if (const grpc::Status status = service_.admit(*context); !status.ok()) {
    finish(status);
    return;
  }
  StartRead(&request_);
}

void StreamReactor::OnReadDone(bool ok) {
  if (!ok) {
    // The client closed its side (or the call broke) before every declared byte arrived.
    finish(context_->IsCancelled() ? grpc::Status::CANCELLED
                                   : grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                                                  header_seen_ ? "stream ended before the uploads were complete"
                                                               : "stream ended before the header"));
    return;
  }
  try {
    if (!header_seen_) {
      if (!request_.has_header()) fail(ErrorCode::kInvalidArgument, "the first message must be the header");
      header_seen_ = true;
      on_header(request_.header());
    } else {
      if (!request_.has_chunk()) fail(ErrorCode::kInvalidArgument, "only chunks may follow the header");
      on_chunk(request_.chunk());
    }
  } catch (...) {
    finish(status_from_current_exception());
    return;
  }
  read_next_or_start_job();
}

void StreamReactor::on_header(const v1::UploadHeader& header) {
  clock_.upload_start = CallClock::Clock::now();
  params_ = params_from_proto(header.params());
  preview_points_ = preview_points_from_proto(header.preview_points());
  source_ = prepare(header.source(), "source", uploads_[0]);
  target_ = prepare(header.target(), "target", uploads_[1]);
}

CloudSource StreamReactor::prepare(const v1::StreamCloud& cloud, const char* role, Upload& upload) {
  switch (cloud.kind_case()) {
    case v1::StreamCloud::kPath:
      upload.complete = true;
      return service_.referenced_cloud(cloud.path());
    case v1::StreamCloud::kUpload: {
      const v1::UploadedFile& file = cloud.upload();
      const std::string name = file.file_name().empty() ? role : file.file_name();
      if (file.size_bytes() > service_.max_upload_bytes)
        fail(ErrorCode::kResourceExhausted,
             fmt::format("{}: {} bytes exceed the upload limit of {} MiB (--max-upload-mb)", name, file.size_bytes(),
                         service_.max_upload_bytes >> 20));
      upload.file = service_.spool.create(name);
      upload.size_bytes = file.size_bytes();
      upload.crc32c = file.crc32c();
      record_.upload_bytes += file.size_bytes();
      CloudSource source{name, upload.file->path(), {}};
      if (upload.size_bytes == 0) verify(upload, source, role);
      return source;
    }
    case v1::StreamCloud::KIND_NOT_SET:
      break;
  }
  fail(ErrorCode::kInvalidArgument, std::string(role) + ": give either path or upload");
}

void StreamReactor::on_chunk(const v1::UploadChunk& chunk) {
  const bool is_source = chunk.role() == v1::CLOUD_ROLE_SOURCE;
  if (!is_source && chunk.role() != v1::CLOUD_ROLE_TARGET)
    fail(ErrorCode::kInvalidArgument, "chunk role must be CLOUD_ROLE_SOURCE or CLOUD_ROLE_TARGET");
  const char* role = is_source ? "source" : "target";
  Upload& upload = uploads_[is_source ? 0 : 1];
  const CloudSource& source = is_source ? source_ : target_;
  if (!upload.file) fail(ErrorCode::kInvalidArgument, fmt::format("chunk for the {}, which is not an upload", role));
  if (upload.complete) fail(ErrorCode::kInvalidArgument, fmt::format("{}: more bytes than declared", source.name));
  if (chunk.data().size() > kMaxChunkBytes)
    fail(ErrorCode::kInvalidArgument,
         fmt::format("{}: chunk of {} bytes, at most {} allowed", source.name, chunk.data().size(), kMaxChunkBytes));
  if (upload.file->size() + chunk.data().size() > upload.size_bytes)
    fail(ErrorCode::kInvalidArgument,
         fmt::format("{}: more bytes than the declared size_bytes {}", source.name, upload.size_bytes));
  upload.file->append(chunk.data());
  if (upload.file->size() == upload.size_bytes) verify(upload, source, role);
}

void StreamReactor::verify(Upload& upload, const CloudSource& source, const char* role) {
  upload.file->close();
  upload.complete = true;
  if (upload.file->crc32c() != upload.crc32c)
    fail(ErrorCode::kDataLoss, fmt::format("{} upload {}: CRC-32C {:08x} of the received bytes, {:08x} declared", role,
                                           source.name, upload.file->crc32c(), upload.crc32c));
}

bool StreamReactor::uploads_complete() const { return uploads_[0].complete && uploads_[1].complete; }

void StreamReactor::read_next_or_start_job() {
  if (!uploads_complete()) {
    StartRead(&request_);
    return;
  }
  clock_.upload_end = CallClock::Clock::now();
  start_job(*context_, clock_, [this](Job& job) { execute(job); });
}

void StreamReactor::execute(Job& job) {
  const StageListener listener = [this](const std::string& stage, v1::StageEvent::Phase phase, double fraction) {
    post_stage(stage, phase, fraction, clock_.job_start);
  };
  v1::RegisterStreamResponse reply;
  const grpc::Status status =
      run_job(service_, job, source_, target_, params_, preview_points_, listener, clock_, record_,
              *reply.mutable_result());
  if (status.ok()) post(std::move(reply));
  finish(status);
}

void StreamReactor::on_finishing(const grpc::Status& status) {
  // Nothing reads the spool files any more (no job and no read in flight at any call of finish), and the
  // client should not see its status before they are gone.
  for (Upload& upload : uploads_) upload.file.reset();
  record_.code = status.error_code();
  record_.error = status.error_message();
  service_.end_request(record_);  // before the status leaves: a client that got its answer finds the log line
}

void StreamReactor::OnDone() { delete this; }

}  // namespace k4reg::service
