#include "remote/local_file.h"

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "commands/command_error.h"
#include "k4reg/util/crc32c.h"

namespace k4reg::cli {
namespace {

[[noreturn]] void fail_read(const std::string& path, int error) {
  throw CommandError("cannot read " + path + ": " + std::strerror(error));
}

}  // namespace

FileReader::FileReader(const std::string& path, std::size_t piece_bytes)
    : path_(path), piece_bytes_(piece_bytes), file_(std::fopen(path.c_str(), "rb")) {
  if (!file_) fail_read(path, errno);
}

FileReader::~FileReader() { std::fclose(file_); }

const std::string& FileReader::next() {
  buffer_.resize(piece_bytes_);
  errno = 0;
  buffer_.resize(std::fread(buffer_.data(), 1, piece_bytes_, file_));
  // A directory opens but fails on the first read (EISDIR).
  if (buffer_.empty() && std::ferror(file_)) fail_read(path_, errno);
  return buffer_;
}

std::string read_local_file(const std::string& path) {
  std::string bytes;
  FileReader reader(path, 1 << 20);
  for (const std::string* piece = &reader.next(); !piece->empty(); piece = &reader.next()) bytes += *piece;
  return bytes;
}

LocalFile describe_local_file(const std::string& path) {
  LocalFile file{path, {}};
  FileReader reader(path, kUploadChunkBytes);
  Crc32c crc;
  std::uint64_t size = 0;
  for (const std::string* piece = &reader.next(); !piece->empty(); piece = &reader.next()) {
    crc.update(*piece);
    size += piece->size();
  }
  file.description.set_file_name(std::filesystem::path(path).filename().string());  // format hint, no local paths
  file.description.set_size_bytes(size);
  file.description.set_crc32c(crc.value());
  return file;
}

}  // namespace k4reg::cli
