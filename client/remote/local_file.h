// Reading the local scans the remote commands send, with messages that name the file and the reason
// ("cannot read scan.ply: No such file or directory").
#pragma once

#include <cstdio>
#include <string>

#include "k4reg/v1/registration.pb.h"

namespace k4reg::cli {

// Reads a file in pieces of at most `piece_bytes`, so a scan of any size passes through a fixed buffer.
// Throws CommandError when the file cannot be opened or read.
class FileReader {
 public:
  FileReader(const std::string& path, std::size_t piece_bytes);
  ~FileReader();
  FileReader(const FileReader&) = delete;
  FileReader& operator=(const FileReader&) = delete;

  // The next piece; empty at the end of the file.
  const std::string& next();

 private:
  std::string path_;
  std::size_t piece_bytes_;
  std::FILE* file_;
  std::string buffer_;
};

// The whole file; throws CommandError as FileReader.
std::string read_local_file(const std::string& path);

// Uploads go in pieces of the protocol's maximum: fewest messages.
constexpr std::size_t kUploadChunkBytes = 1 << 20;

// A local file to upload and its header description (name without local directories, size, CRC-32C). Files
// are read twice, once here and once while sending, so a scan of any size streams through a 1 MiB buffer
// instead of being held in memory. Throws CommandError as FileReader.
struct LocalFile {
  std::string path;
  v1::UploadedFile description;
};
LocalFile describe_local_file(const std::string& path);

}  // namespace k4reg::cli
