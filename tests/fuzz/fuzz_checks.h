// What every fuzz target asserts about an outcome, beyond "no crash, no sanitizer report": a cloud that was
// read is well-formed, and a refusal is a typed k4reg::Error that names the input and is not a bug
// (kInternal). Anything else — another exception type such as std::bad_alloc or std::out_of_range, or a
// broken invariant — aborts, and libFuzzer keeps the input as a finding.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "k4reg/util/error.h"
#include "k4reg/geometry/point_cloud.h"

namespace k4reg::fuzz {

[[noreturn]] inline void finding(const std::string& what) {
  std::fprintf(stderr, "fuzz invariant broken: %s\n", what.c_str());
  std::abort();
}

inline void check_cloud(const PointCloud& cloud) {
  if (cloud.empty()) finding("a reader returned an empty cloud instead of refusing it");
  if (!cloud.intensity.empty() && cloud.intensity.size() != cloud.points.size())
    finding("intensity and point counts differ");
  if (!cloud.origin_m.allFinite()) finding("non-finite origin");
  for (const auto& p : cloud.points)
    if (!p.allFinite()) finding("non-finite point");
}

// A refusal must carry the name the caller gave (clients see it) and a code other than kInternal. A client's
// name may hold a NUL byte; what() ends there, so only the part before it is required.
inline void check_error(const Error& error, const std::string& name) {
  if (error.code() == ErrorCode::kInternal) finding(std::string("kInternal for user input: ") + error.what());
  const std::string visible = name.substr(0, name.find('\0'));
  if (std::string(error.what()).find(visible) == std::string::npos)
    finding("the message does not name the input '" + visible + "': " + error.what());
}

// Runs `read` (returning a PointCloud) and checks whichever outcome it has.
template <typename Read>
void check_read(const std::string& name, Read&& read) {
  try {
    check_cloud(read());
  } catch (const Error& e) {
    check_error(e, name);
  }
}

}  // namespace k4reg::fuzz
