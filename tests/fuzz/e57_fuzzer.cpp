// The E57 reader on arbitrary bytes. Every 1024-byte page ends in the CRC-32C of its data, so nearly every mutation
// would stop at the first page check: for inputs whose first byte is odd, the harness rewrites each page's CRC
// before reading (dropping that byte), so that the fuzzer reaches the XML, the section headers and the bit-packed
// data; even inputs go in as they are, which covers the CRC checks themselves.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_checks.h"
#include "k4reg/util/crc32c.h"
#include "k4reg/io/e57_io.h"

namespace {

constexpr std::size_t kPage = 1024, kPageData = 1020;

// The CRC of each whole page, stored most significant byte first as the reader expects.
void rewrite_page_crcs(std::string& file) {
  for (std::size_t page = 0; page + kPage <= file.size(); page += kPage) {
    const std::uint32_t crc = k4reg::crc32c(std::string_view(file.data() + page, kPageData));
    for (int k = 0; k < 4; ++k) file[page + kPageData + k] = static_cast<char>(crc >> (24 - 8 * k));
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  std::string file(reinterpret_cast<const char*>(data) + 1, size - 1);
  if (data[0] & 1) rewrite_page_crcs(file);
  const std::string name = "scan.e57";
  k4reg::fuzz::check_read(name, [&] { return k4reg::read_e57_bytes(file, name, k4reg::ReadOptions{}); });
  return 0;
}
