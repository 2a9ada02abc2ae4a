#include "local_file.h"

#include <cerrno>
#include <cstring>

#include "command_error.h"

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

}  // namespace k4reg::cli
