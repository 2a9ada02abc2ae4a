// Spooling of streamed uploads: each upload goes to a file in a per-process directory, never into one
// big in-memory buffer. The directory is <spool_dir>/k4reg-spool-<host>-<pid>; at start-up it is
// emptied and the directories of this host's dead processes are removed, so a crash leaves nothing behind
// for long. A SpoolFile deletes itself when dropped (success, failure or cancellation alike). At most
// `max_files` exist at once (--max-spool-files): each holds disk and, while it receives, a descriptor, and
// uploads are declared before a byte of them arrives.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

#include "k4reg/util/crc32c.h"

namespace k4reg::service {

class SpoolFile {
 public:
  SpoolFile(const SpoolFile&) = delete;
  SpoolFile& operator=(const SpoolFile&) = delete;
  ~SpoolFile();

  // Throws k4reg::Error: kResourceExhausted when the disk is full, kInternal on other write errors.
  void append(std::string_view data);
  // Flushes and closes the file so it can be read; no append afterwards.
  void close();

  const std::string& path() const { return path_; }
  std::uint64_t size() const { return size_; }
  std::uint32_t crc32c() const { return crc_.value(); }

 private:
  friend class SpoolDir;
  SpoolFile(std::string path, int fd, std::atomic<std::size_t>& live) : path_(std::move(path)), fd_(fd), live_(live) {}

  std::string path_;
  int fd_;
  std::atomic<std::size_t>& live_;  // the directory's count of files
  std::uint64_t size_ = 0;
  Crc32c crc_;
};

class SpoolDir {
 public:
  // Throws k4reg::Error(kInvalidArgument) if the directory cannot be created.
  explicit SpoolDir(const std::filesystem::path& parent, std::size_t max_files = 1000);
  SpoolDir(const SpoolDir&) = delete;
  SpoolDir& operator=(const SpoolDir&) = delete;
  ~SpoolDir();

  // A new empty file. `file_name` is the client's name: only its extension is kept (the readers use it
  // as a format hint), never its directories. Thread-safe. Throws k4reg::Error: kResourceExhausted when
  // max_files exist already (naming --max-spool-files), kInternal when the file cannot be created.
  std::unique_ptr<SpoolFile> create(const std::string& file_name);

  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  const std::size_t max_files_;
  std::atomic<std::size_t> live_{0};
};

}  // namespace k4reg::service
