// The paged layer of E57 files (private to the core): 1024-byte physical pages, each 1020 bytes of data and the
// CRC-32C of those bytes (stored most significant byte first, as libE57Format writes it).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "e57_format.h"
#include "io_common.h"

namespace k4reg::e57 {

// Reads the logical byte stream of a paged file held in memory. Every page is CRC-checked the first time any
// of its bytes is read; a mismatch is kDataLoss naming the page.
class PagedReader {
 public:
  // `pages` whole pages of `file` (the caller has checked the file holds them).
  PagedReader(std::string_view file, std::uint64_t pages, const std::string& name);

  std::uint64_t logical_size() const { return pages_ * kPageData; }
  // Copies `size` logical bytes from `logical` into `out`; kInvalidArgument if they pass the end.
  void read(std::uint64_t logical, std::size_t size, char* out);
  std::string read(std::uint64_t logical, std::size_t size);

 private:
  void verify(std::uint64_t page);

  std::string_view file_;
  std::uint64_t pages_;
  const std::string& name_;
  std::vector<bool> verified_;
};

// Writes a logical byte stream as pages with their CRCs.
class PagedWriter {
 public:
  explicit PagedWriter(io_detail::OutputFile& out) : out_(out) {}
  void write(std::string_view bytes);
  // Zero-fills and writes the last page.
  void finish();
  std::uint64_t logical_position() const { return logical_; }

 private:
  io_detail::OutputFile& out_;
  char page_[kPageSize] = {};
  std::size_t used_ = 0;
  std::uint64_t logical_ = 0;
};

}  // namespace k4reg::e57
