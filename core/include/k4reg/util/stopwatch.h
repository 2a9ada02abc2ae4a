// Wall-clock helpers on the steady clock: how long a stage or a job took, and the deadline a time budget
// sets. Cost: a clock read.
#pragma once

#include <chrono>

namespace k4reg {

using SteadyClock = std::chrono::steady_clock;

inline double seconds_since(SteadyClock::time_point start) {
  return std::chrono::duration<double>(SteadyClock::now() - start).count();
}

// The instant `seconds` from now (a time budget's deadline).
inline SteadyClock::time_point deadline_in(double seconds) {
  return SteadyClock::now() + std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(seconds));
}

}  // namespace k4reg
