// CRC-32C (Castagnoli): the checksum of every 1024-byte E57 page (e57_io) and of streamed uploads (the
// client computes it over the file it sends, the server over the bytes it spooled). For uploads it was chosen
// over SHA-256 because it is cheap enough to compute while spooling (slicing-by-8, ~2 GB/s) and the threat is
// corruption, not tampering (TLS covers that).
#pragma once

#include <cstdint>
#include <string_view>

namespace k4reg {

// Incremental: feed the file in any number of pieces.
class Crc32c {
 public:
  void update(std::string_view data);
  std::uint32_t value() const { return ~state_; }

 private:
  std::uint32_t state_ = 0xFFFFFFFFu;
};

std::uint32_t crc32c(std::string_view data);

}  // namespace k4reg
