// E57 (ASTM E2807) binary layout shared by the reader and the writer (private to the core). References: the
// standard's sections on the paged file, the CompressedVector binary section and the bitPackCodec, as
// implemented by libE57Format (CheckedFile, SectionHeaders, Packet, Encoder/Decoder).
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace k4reg::e57 {

// The file is a sequence of 1024-byte physical pages: 1020 bytes of data then the page's CRC-32C. Offsets in
// the file header and the XML are physical; everything else (sections, packets) is addressed in the logical
// byte stream of the concatenated page data.
constexpr std::size_t kPageSize = 1024;
constexpr std::size_t kPageData = 1020;

// File header (logical offset 0): char signature[8] "ASTM-E57", u32 major, u32 minor, u64 filePhysicalLength,
// u64 xmlPhysicalOffset, u64 xmlLogicalLength, u64 pageSize.
constexpr std::size_t kFileHeaderSize = 48;
constexpr char kSignature[] = "ASTM-E57";

// CompressedVector section header: u8 sectionId (1), 7 reserved, u64 sectionLogicalLength,
// u64 dataPhysicalOffset, u64 indexPhysicalOffset.
constexpr std::size_t kSectionHeaderSize = 32;
constexpr unsigned char kCompressedVectorSection = 1;

// Packets: u8 type, u8 flags, u16 packetLogicalLength - 1, ... A data packet continues with u16 bytestreamCount,
// one u16 buffer length per bytestream, then the buffers in bytestream order; its length is a multiple of 4
// (zero padding) and at most 64 KiB.
constexpr unsigned char kIndexPacket = 0, kDataPacket = 1, kEmptyPacket = 2;
constexpr std::size_t kDataPacketHeaderSize = 6;
constexpr std::size_t kMaxPacketSize = 65536;

inline std::uint64_t logical_to_physical(std::uint64_t logical) {
  return logical / kPageData * kPageSize + logical % kPageData;
}

// False for an offset inside a page's CRC.
inline bool physical_to_logical(std::uint64_t physical, std::uint64_t& logical) {
  if (physical % kPageSize >= kPageData) return false;
  logical = physical / kPageSize * kPageData + physical % kPageSize;
  return true;
}

// The bitPackCodec stores Integer and ScaledInteger values as (value - minimum) in the fewest bits that hold
// maximum - minimum; 0 bits for a constant.
inline unsigned bits_needed(std::int64_t minimum, std::int64_t maximum) {
  return static_cast<unsigned>(std::bit_width(static_cast<std::uint64_t>(maximum) - static_cast<std::uint64_t>(minimum)));
}

// How one field of a CompressedVector prototype is stored in its bytestream.
struct FieldCodec {
  enum class Type { kFloat, kInteger, kScaledInteger, kString };
  Type type = Type::kFloat;
  bool single_precision = false;  // Float
  std::int64_t minimum = 0, maximum = 0;  // Integer, ScaledInteger
  double scale = 1.0, offset = 0.0;       // ScaledInteger: value = integer * scale + offset

  // Bits per record in the bytestream (Float: 32 or 64).
  unsigned bits() const {
    if (type == Type::kFloat) return single_precision ? 32 : 64;
    return bits_needed(minimum, maximum);
  }
  // The stored integer (Integer/ScaledInteger) for packed bits `raw`; raw must not exceed maximum - minimum.
  std::int64_t integer(std::uint64_t raw) const {
    return static_cast<std::int64_t>(static_cast<std::uint64_t>(minimum) + raw);
  }
  // The field's value for packed bits `raw`.
  double value(std::uint64_t raw) const {
    switch (type) {
      case Type::kFloat:
        if (single_precision) return std::bit_cast<float>(static_cast<std::uint32_t>(raw));
        return std::bit_cast<double>(raw);
      case Type::kInteger:
        return static_cast<double>(integer(raw));
      case Type::kScaledInteger:
        return static_cast<double>(integer(raw)) * scale + offset;
      case Type::kString:
        break;
    }
    return 0.0;
  }
};

}  // namespace k4reg::e57
