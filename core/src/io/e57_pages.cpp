#include "e57_pages.h"

#include <algorithm>
#include <cstring>

#include "e57_format.h"
#include "k4reg/util/crc32c.h"
#include "k4reg/util/error.h"

namespace k4reg::e57 {
namespace {

std::uint32_t page_crc(const char* page) { return crc32c(std::string_view(page, kPageData)); }

void store_crc(char* page, std::uint32_t crc) {
  for (int k = 0; k < 4; ++k) page[kPageData + k] = static_cast<char>(crc >> (24 - 8 * k));
}

std::uint32_t stored_crc(const char* page) {
  std::uint32_t crc = 0;
  for (int k = 0; k < 4; ++k) crc = (crc << 8) | static_cast<unsigned char>(page[kPageData + k]);
  return crc;
}

}  // namespace

PagedReader::PagedReader(std::string_view file, std::uint64_t pages, const std::string& name)
    : file_(file), pages_(pages), name_(name), verified_(pages, false) {}

void PagedReader::verify(std::uint64_t page) {
  if (verified_[page]) return;
  const char* data = file_.data() + page * kPageSize;
  const std::uint32_t computed = page_crc(data), stored = stored_crc(data);
  if (computed != stored) {
    char text[96];
    std::snprintf(text, sizeof text, "CRC-32C mismatch in page %llu (bytes %llu-%llu): stored %08x, computed %08x",
                  static_cast<unsigned long long>(page), static_cast<unsigned long long>(page * kPageSize),
                  static_cast<unsigned long long>(page * kPageSize + kPageSize - 1), stored, computed);
    io_detail::fail_io(ErrorCode::kDataLoss, name_, std::string(text) + ": the file is corrupt");
  }
  verified_[page] = true;
}

void PagedReader::read(std::uint64_t logical, std::size_t size, char* out) {
  if (logical > logical_size() || size > logical_size() - logical)
    io_detail::fail_io(ErrorCode::kInvalidArgument, name_,
                       "truncated: " + std::to_string(size) + " bytes at logical offset " + std::to_string(logical) +
                           " pass the end of the data (" + std::to_string(logical_size()) + " bytes)");
  while (size > 0) {
    const std::uint64_t page = logical / kPageData;
    const std::size_t in_page = logical % kPageData, n = std::min(size, kPageData - in_page);
    verify(page);
    std::memcpy(out, file_.data() + page * kPageSize + in_page, n);
    out += n;
    size -= n;
    logical += n;
  }
}

std::string PagedReader::read(std::uint64_t logical, std::size_t size) {
  std::string bytes(size, '\0');
  read(logical, size, bytes.data());
  return bytes;
}

void PagedWriter::write(std::string_view bytes) {
  while (!bytes.empty()) {
    const std::size_t n = std::min(bytes.size(), kPageData - used_);
    std::memcpy(page_ + used_, bytes.data(), n);
    used_ += n;
    logical_ += n;
    bytes.remove_prefix(n);
    if (used_ == kPageData) {
      store_crc(page_, page_crc(page_));
      out_.write(page_, kPageSize);
      used_ = 0;
    }
  }
}

void PagedWriter::finish() {
  if (used_ == 0) return;
  std::memset(page_ + used_, 0, kPageData - used_);
  store_crc(page_, page_crc(page_));
  out_.write(page_, kPageSize);
  used_ = 0;
}

}  // namespace k4reg::e57
