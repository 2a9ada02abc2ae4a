#include "jobs/cloud_bytes.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <utility>

#include "k4reg/util/error.h"
#include "security/path_policy.h"

namespace k4reg::service {
namespace {

// Spool files are the server's own: opened as they are, still never waiting on anything but a regular file.
int open_spool_file(const CloudSource& source) {
  const int fd = ::open(source.file.c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK | O_NOFOLLOW);
  if (fd < 0) fail(ErrorCode::kNotFound, source.name + ": the uploaded file is gone");
  struct stat status {};
  if (::fstat(fd, &status) != 0 || !S_ISREG(status.st_mode)) {
    ::close(fd);
    fail(ErrorCode::kInvalidArgument, source.name + ": not a regular file");
  }
  return fd;
}

}  // namespace

CloudBytes::CloudBytes(const CloudSource& source) : bytes_(source.bytes) {
  if (source.file.empty()) return;
  const int fd = source.paths ? source.paths->open(source.file, source.name) : open_spool_file(source);
  struct stat status {};
  const bool sized = ::fstat(fd, &status) == 0;
  const std::size_t size = sized ? static_cast<std::size_t>(status.st_size) : 0;
  void* mapping = size == 0 ? nullptr : ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE, fd, 0);
  ::close(fd);
  if (!sized || mapping == MAP_FAILED) fail(ErrorCode::kInternal, source.name + ": cannot map the file");
  if (mapping) ::madvise(mapping, size, MADV_SEQUENTIAL);
  mapping_ = mapping;
  bytes_ = {static_cast<const char*>(mapping), size};
}

CloudBytes::CloudBytes(CloudBytes&& other) noexcept
    : mapping_(std::exchange(other.mapping_, nullptr)), bytes_(other.bytes_) {}

CloudBytes::~CloudBytes() {
  if (mapping_) ::munmap(mapping_, bytes_.size());
}

}  // namespace k4reg::service
