// Reading the local scans the remote commands send, with messages that name the file and the reason
// ("cannot read scan.ply: No such file or directory").
#pragma once

#include <cstdio>
#include <string>

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

}  // namespace k4reg::cli
