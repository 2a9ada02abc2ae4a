#include "k4reg/util/stage_timing.h"

#include <algorithm>

namespace k4reg {

void add_timing(std::vector<StageTiming>& timings, const std::string& stage, double seconds) {
  auto same = std::find_if(timings.begin(), timings.end(), [&](const StageTiming& t) { return t.stage == stage; });
  if (same != timings.end())
    same->seconds += seconds;
  else
    timings.push_back({stage, seconds});
}

void add_timings(std::vector<StageTiming>& total, const std::vector<StageTiming>& more) {
  for (const StageTiming& t : more) add_timing(total, t.stage, t.seconds);
}

}  // namespace k4reg
