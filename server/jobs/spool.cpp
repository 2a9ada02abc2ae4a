#include "jobs/spool.h"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstring>

#include "k4reg/util/error.h"

namespace k4reg::service {
namespace fs = std::filesystem;
namespace {

constexpr std::string_view kPrefix = "k4reg-spool-";

std::string host_name() {
  char name[256] = {};
  if (gethostname(name, sizeof name - 1) != 0) return "unknown";
  std::string host(name);
  for (char& c : host)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.') c = '_';
  return host;
}

// Removes <prefix><host>-<pid> directories whose process no longer runs (a crashed or killed server).
void remove_stale_dirs(const fs::path& parent, const std::string& host_prefix) {
  std::error_code ec;
  for (const fs::directory_entry& entry : fs::directory_iterator(parent, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(host_prefix, 0) != 0) continue;
    const std::string pid_text = name.substr(host_prefix.size());
    if (pid_text.empty() || pid_text.find_first_not_of("0123456789") != std::string::npos) continue;
    const long pid = std::stol(pid_text);
    if (kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM) continue;  // still alive
    fs::remove_all(entry.path(), ec);
  }
}

std::string safe_extension(const std::string& file_name) {
  std::string ext = fs::path(file_name).extension().string();
  if (ext.size() > 16) return {};
  for (std::size_t i = 1; i < ext.size(); ++i)
    if (!std::isalnum(static_cast<unsigned char>(ext[i]))) return {};
  return ext;
}

}  // namespace

SpoolFile::~SpoolFile() {
  if (fd_ >= 0) ::close(fd_);
  std::error_code ec;
  fs::remove(path_, ec);
  --live_;
}

void SpoolFile::append(std::string_view data) {
  crc_.update(data);
  size_ += data.size();
  while (!data.empty()) {
    const ssize_t written = ::write(fd_, data.data(), data.size());
    if (written < 0) {
      if (errno == EINTR) continue;
      const int error = errno;
      fail(error == ENOSPC || error == EDQUOT ? ErrorCode::kResourceExhausted : ErrorCode::kInternal,
           std::string("cannot spool the upload: ") + std::strerror(error));
    }
    data.remove_prefix(static_cast<std::size_t>(written));
  }
}

void SpoolFile::close() {
  if (fd_ < 0) return;
  const int result = ::close(fd_);
  fd_ = -1;
  if (result != 0) fail(ErrorCode::kInternal, std::string("cannot spool the upload: ") + std::strerror(errno));
}

SpoolDir::SpoolDir(const fs::path& parent, std::size_t max_files) : max_files_(max_files) {
  const std::string host_prefix = std::string(kPrefix) + host_name() + "-";
  path_ = parent / (host_prefix + std::to_string(getpid()));
  std::error_code ec;
  fs::create_directories(parent, ec);
  remove_stale_dirs(parent, host_prefix);
  fs::remove_all(path_, ec);  // left by an earlier process with our pid (containers: always pid 1)
  if (!fs::create_directory(path_, ec) || ec)
    fail(ErrorCode::kInvalidArgument, "cannot create the spool directory " + path_.string() + ": " + ec.message());
  fs::permissions(path_, fs::perms::owner_all, ec);
}

SpoolDir::~SpoolDir() {
  std::error_code ec;
  fs::remove_all(path_, ec);
}

std::unique_ptr<SpoolFile> SpoolDir::create(const std::string& file_name) {
  if (++live_ > max_files_) {
    --live_;
    fail(ErrorCode::kResourceExhausted, "uploads in flight on this server already hold " + std::to_string(max_files_) +
                                            " spool files (--max-spool-files); retry later");
  }
  static std::atomic<std::uint64_t> counter{0};
  const std::string path = (path_ / ("upload-" + std::to_string(++counter) + safe_extension(file_name))).string();
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) {
    const int error = errno;
    --live_;
    fail(ErrorCode::kInternal, "cannot create a spool file: " + std::string(std::strerror(error)));
  }
  return std::unique_ptr<SpoolFile>(new SpoolFile(path, fd, live_));
}

}  // namespace k4reg::service
