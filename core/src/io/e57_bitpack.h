// The E57 bitPackCodec's bit streams (private to the core): each prototype field is a bytestream of fixed-width
// values packed least-significant bit first, continuing across data packets (a value may straddle two packets).
// Floats are the same stream with 32- or 64-bit values.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "io_common.h"

namespace k4reg::e57 {

class BitPacker {
 public:
  // Appends the low `bits` (0–64) bits of value.
  void put(std::uint64_t value, unsigned bits) {
    if (bits > 32) {
      put(value & 0xFFFFFFFFu, 32);
      put(value >> 32, bits - 32);
      return;
    }
    if (bits == 0) return;
    pending_ |= (value & ((std::uint64_t{1} << bits) - 1)) << pending_bits_;
    pending_bits_ += bits;
    for (; pending_bits_ >= 8; pending_bits_ -= 8, pending_ >>= 8) bytes_.push_back(static_cast<char>(pending_ & 0xFF));
  }
  // The complete bytes so far; the caller takes them (e.g. into a packet) and clears the string.
  std::string& bytes() { return bytes_; }
  // Completes the last byte with zero bits (end of the stream).
  void finish() {
    if (pending_bits_ > 0) bytes_.push_back(static_cast<char>(pending_ & 0xFF));
    pending_ = 0;
    pending_bits_ = 0;
  }

 private:
  std::string bytes_;
  std::uint64_t pending_ = 0;  // fewer than 8 bits between put() calls
  unsigned pending_bits_ = 0;
};

class BitUnpacker {
 public:
  explicit BitUnpacker(unsigned bits) : bits_(bits) {}

  // Appends the next piece of the stream, then calls out(raw) for each complete value, at most `limit` of them.
  // Returns how many values were produced; the incomplete rest waits for the next piece.
  template <typename Out>
  std::uint64_t unpack(std::string_view piece, std::uint64_t limit, Out&& out) {
    buffer_.append(piece);
    const auto* bytes = reinterpret_cast<const unsigned char*>(buffer_.data());
    const std::size_t size = buffer_.size(), total_bits = 8 * size;
    std::size_t position = first_bit_;
    std::uint64_t produced = 0;
    for (; produced < limit && position + bits_ <= total_bits; ++produced, position += bits_)
      out(read(bytes, size, position));
    buffer_.erase(0, position / 8);
    first_bit_ = static_cast<unsigned>(position % 8);
    return produced;
  }

 private:
  // The `bits_` bits from bit `position` on (all of them lie inside the buffer).
  std::uint64_t read(const unsigned char* bytes, std::size_t size, std::size_t position) const {
    const std::size_t byte = position / 8;
    const unsigned shift = position % 8;
    std::uint64_t word = 0;
    if (byte + 8 <= size) {
      word = io_detail::load_le<std::uint64_t>(reinterpret_cast<const char*>(bytes + byte)) >> shift;
      if (shift + bits_ > 64) word |= std::uint64_t{bytes[byte + 8]} << (64 - shift);
    } else {
      for (std::size_t k = 0; byte + k < size; ++k) word |= std::uint64_t{bytes[byte + k]} << (8 * k);
      word >>= shift;
    }
    return bits_ == 64 ? word : word & ((std::uint64_t{1} << bits_) - 1);
  }

  unsigned bits_;
  std::string buffer_;      // bytes not completely consumed yet
  unsigned first_bit_ = 0;  // bits of buffer_[0] already consumed
};

}  // namespace k4reg::e57
