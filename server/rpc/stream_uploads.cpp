#include "rpc/stream_uploads.h"

#include <fmt/format.h>

#include <algorithm>

#include "k4reg/util/error.h"

namespace k4reg::service {
namespace {

constexpr std::size_t kMaxChunkBytes = 1 << 20;

}  // namespace

CloudSource StreamUploads::add(const v1::StreamCloud& cloud, const std::string& role) {
  Upload& upload = uploads_.emplace_back();
  upload.role = role;
  switch (cloud.kind_case()) {
    case v1::StreamCloud::kPath: {
      upload.complete = true;
      CloudSource source = service_.referenced_cloud(cloud.path());
      upload.name = source.name;
      return source;
    }
    case v1::StreamCloud::kUpload: {
      const v1::UploadedFile& file = cloud.upload();
      upload.name = file.file_name().empty() ? role : file.file_name();
      if (file.size_bytes() > service_.max_upload_bytes)
        fail(ErrorCode::kResourceExhausted,
             fmt::format("{}: {} bytes exceed the upload limit of {} MiB (--max-upload-mb)", upload.name,
                         file.size_bytes(), service_.max_upload_bytes >> 20));
      upload.file = service_.spool.create(upload.name);
      upload.size_bytes = file.size_bytes();
      upload.crc32c = file.crc32c();
      declared_bytes_ += file.size_bytes();
      CloudSource source{upload.name, upload.file->path(), {}};
      if (upload.size_bytes == 0) verify(upload);
      return source;
    }
    case v1::StreamCloud::KIND_NOT_SET:
      break;
  }
  fail(ErrorCode::kInvalidArgument, role + ": give either path or upload");
}

void StreamUploads::append(std::size_t index, const std::string& data) {
  if (index >= uploads_.size()) fail(ErrorCode::kInvalidArgument, fmt::format("chunk for cloud {}, which the header does not name", index));
  Upload& upload = uploads_[index];
  if (!upload.file) fail(ErrorCode::kInvalidArgument, fmt::format("chunk for the {}, which is not an upload", upload.role));
  if (upload.complete) fail(ErrorCode::kInvalidArgument, fmt::format("{}: more bytes than declared", upload.name));
  if (data.size() > kMaxChunkBytes)
    fail(ErrorCode::kInvalidArgument,
         fmt::format("{}: chunk of {} bytes, at most {} allowed", upload.name, data.size(), kMaxChunkBytes));
  if (upload.file->size() + data.size() > upload.size_bytes)
    fail(ErrorCode::kInvalidArgument,
         fmt::format("{}: more bytes than the declared size_bytes {}", upload.name, upload.size_bytes));
  upload.file->append(data);
  if (upload.file->size() == upload.size_bytes) verify(upload);
}

void StreamUploads::verify(Upload& upload) {
  upload.file->close();
  upload.complete = true;
  if (upload.file->crc32c() != upload.crc32c)
    fail(ErrorCode::kDataLoss, fmt::format("{} upload {}: CRC-32C {:08x} of the received bytes, {:08x} declared",
                                           upload.role, upload.name, upload.file->crc32c(), upload.crc32c));
}

bool StreamUploads::complete() const {
  return std::all_of(uploads_.begin(), uploads_.end(), [](const Upload& u) { return u.complete; });
}

}  // namespace k4reg::service
