// read_cloud_bytes: format detection by content with the extension as a hint, then the chosen reader, as for
// an upload or an inline cloud. The first input byte picks the file name (and so the hint); the rest is the file.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_checks.h"
#include "k4reg/io/cloud_io.h"

namespace {

// Every extension a client may send, plus none and an unknown one.
constexpr const char* kNames[] = {"scan.ply", "scan.pcd", "scan.xyz", "scan.txt", "scan.pts", "scan.csv",
                                  "scan.asc", "scan.las", "scan.laz", "scan.ptx", "scan.e57", "scan",
                                  "scan.bin", "SCAN.PLY", "dir.ply/scan"};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string name = kNames[data[0] % std::size(kNames)];
  const std::string_view bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
  k4reg::fuzz::check_read(name, [&] { return k4reg::read_cloud_bytes(bytes, name); });
  return 0;
}
