// One reader on arbitrary bytes, bypassing format detection. Compiled once per reader (tests/fuzz/CMakeLists.txt):
// K4REG_FUZZ_HEADER is the reader's header, K4REG_FUZZ_READ its read_*_bytes function, K4REG_FUZZ_NAME the
// file name handed to it. No point limit (ReadOptions{}): memory must stay bounded by the input size alone,
// which -malloc_limit_mb in scripts/fuzz.sh enforces.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include K4REG_FUZZ_HEADER
#include "fuzz_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const std::string name = K4REG_FUZZ_NAME;
  k4reg::fuzz::check_read(name, [&] { return K4REG_FUZZ_READ(bytes, name, k4reg::ReadOptions{}); });
  return 0;
}
