// The files a streaming call uploads (RegisterStream, RegisterProjectStream): each cloud its header names is
// a path on the server or an upload that follows in chunks of at most 1 MiB, spooled to a file whose size and
// CRC-32C are checked against the header's when its last byte arrives.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "k4reg/v1/registration.pb.h"
#include "jobs/registration_job.h"
#include "service_context.h"

namespace k4reg::service {

class StreamUploads {
 public:
  explicit StreamUploads(ServiceContext& service) : service_(service) {}

  // The cloud the header names, as the job will read it; `role` names it in messages ("source", "scan 3")
  // and stands in for a missing file name. Throws k4reg::Error: the path errors of PathPolicy::resolve,
  // kResourceExhausted over --max-upload-mb, kInvalidArgument when neither path nor upload is given.
  CloudSource add(const v1::StreamCloud& cloud, const std::string& role);
  // Appends a chunk to upload `index` (in the order added). Throws kInvalidArgument for an index that is no
  // upload, a chunk over 1 MiB or past the declared size, kDataLoss when the finished file's CRC-32C differs.
  void append(std::size_t index, const std::string& data);
  bool complete() const;
  std::uint64_t declared_bytes() const { return declared_bytes_; }
  // Removes the spool files (once nothing reads them).
  void clear() { uploads_.clear(); }

 private:
  struct Upload {
    std::string name, role;
    std::unique_ptr<SpoolFile> file;  // null: this cloud is a path reference
    std::uint64_t size_bytes = 0;
    std::uint32_t crc32c = 0;
    bool complete = false;
  };
  void verify(Upload& upload);

  ServiceContext& service_;
  std::vector<Upload> uploads_;
  std::uint64_t declared_bytes_ = 0;
};

}  // namespace k4reg::service
