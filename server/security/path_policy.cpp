#include "security/path_policy.h"

#include <fcntl.h>
#include <linux/openat2.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <utility>

#include "k4reg/util/error.h"

namespace k4reg::service {
namespace fs = std::filesystem;
namespace {

constexpr int kReadFlags = O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK;  // a FIFO opens without waiting for a writer

// Closes a descriptor when dropped unless released.
struct Descriptor {
  int fd = -1;
  ~Descriptor() {
    if (fd >= 0) ::close(fd);
  }
  int release() { return std::exchange(fd, -1); }
};

// Without openat2 (Linux < 5.6, some seccomp profiles): component by component, following no symlink. resolve()
// returned a path without symlinks, so one found now was swapped in after it.
int open_following_no_symlink(int root, const fs::path& relative) {
  Descriptor directory{::dup(root)};
  std::vector<fs::path> parts(relative.begin(), relative.end());
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    Descriptor next{::openat(directory.fd, parts[i].c_str(), O_PATH | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC)};
    if (next.fd < 0) return -1;
    std::swap(directory.fd, next.fd);
  }
  return ::openat(directory.fd, parts.back().c_str(), kReadFlags | O_NOFOLLOW);
}

int open_beneath(int root, const fs::path& relative) {
  open_how how{};
  how.flags = kReadFlags;
  how.resolve = RESOLVE_BENEATH | RESOLVE_NO_MAGICLINKS;
  const long fd = ::syscall(SYS_openat2, root, relative.c_str(), &how, sizeof how);
  if (fd >= 0 || (errno != ENOSYS && errno != EPERM)) return static_cast<int>(fd);
  return open_following_no_symlink(root, relative);
}

}  // namespace

PathPolicy::PathPolicy(const std::vector<std::string>& roots) {
  for (const std::string& root : roots) {
    std::error_code ec;
    const fs::path canonical = fs::canonical(root, ec);
    if (ec || !fs::is_directory(canonical))
      fail(ErrorCode::kInvalidArgument, "data root " + root + " is not an existing directory");
    roots_.push_back(canonical);
  }
}

const fs::path* PathPolicy::root_of(const fs::path& canonical) const {
  const auto found = std::find_if(roots_.begin(), roots_.end(), [&](const fs::path& root) {
    // Component-wise prefix: "/data/scans2" is not inside "/data/scans".
    return std::mismatch(root.begin(), root.end(), canonical.begin(), canonical.end()).first == root.end();
  });
  return found == roots_.end() ? nullptr : &*found;
}

std::string PathPolicy::resolve(const std::string& requested) const {
  if (requested.empty()) fail(ErrorCode::kInvalidArgument, "empty path");
  if (requested.find('\0') != std::string::npos) fail(ErrorCode::kInvalidArgument, "path contains a NUL byte");
  const fs::path path(requested);
  std::vector<fs::path> candidates;
  if (path.is_absolute())
    candidates.push_back(path);
  else
    for (const fs::path& root : roots_) candidates.push_back(root / path);

  bool missing_inside = false;
  for (const fs::path& candidate : candidates) {
    std::error_code ec;
    // Resolves symlinks along the existing part of the path and normalises the rest lexically.
    const fs::path resolved = fs::weakly_canonical(candidate, ec);
    if (ec || !root_of(resolved)) continue;
    const fs::file_status status = fs::status(resolved, ec);
    if (ec || !fs::exists(status)) {
      missing_inside = true;
      continue;
    }
    if (!fs::is_regular_file(status)) fail(ErrorCode::kInvalidArgument, requested + ": not a regular file");
    return resolved.string();
  }
  if (missing_inside) fail(ErrorCode::kNotFound, requested + ": no such file under the data roots");
  fail(ErrorCode::kPermissionDenied, requested + ": outside the server's data roots");
}

int PathPolicy::open(const std::string& resolved, const std::string& requested) const {
  const fs::path path(resolved);
  const fs::path* root = root_of(path);
  const fs::path relative = root ? path.lexically_relative(*root) : fs::path();
  if (relative.empty() || relative == ".") fail(ErrorCode::kPermissionDenied, requested + ": outside the server's data roots");
  const Descriptor root_fd{::open(root->c_str(), O_PATH | O_DIRECTORY | O_CLOEXEC)};
  Descriptor file{root_fd.fd < 0 ? -1 : open_beneath(root_fd.fd, relative)};
  if (file.fd < 0) {
    const int error = errno;
    if (error == ENOENT) fail(ErrorCode::kNotFound, requested + ": no such file under the data roots");
    if (error == EXDEV || error == ELOOP || error == ENOTDIR)  // a symlink leading out, or one swapped in
      fail(ErrorCode::kPermissionDenied, requested + ": outside the server's data roots");
    if (error == EACCES || error == EPERM) fail(ErrorCode::kPermissionDenied, requested + ": cannot be read by the server");
    fail(ErrorCode::kInvalidArgument, requested + ": cannot be opened: " + std::strerror(error));
  }
  struct stat status {};
  if (::fstat(file.fd, &status) != 0 || !S_ISREG(status.st_mode))
    fail(ErrorCode::kInvalidArgument, requested + ": not a regular file");
  ::fcntl(file.fd, F_SETFL, ::fcntl(file.fd, F_GETFL) & ~O_NONBLOCK);
  return file.release();
}

}  // namespace k4reg::service
