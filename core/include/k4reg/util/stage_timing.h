// Time per named stage of a registration or a project (what `timings` in their results report). Cost: a clock
// read per stage and a scan of the few stages so far.
#pragma once

#include <string>
#include <vector>

#include "k4reg/util/cancellation.h"
#include "k4reg/util/stopwatch.h"

namespace k4reg {

struct StageTiming {
  std::string stage;
  double seconds = 0.0;
};

// Adds seconds to the stage's entry (appended where the stage is new): a stage run more than once reports its total.
void add_timing(std::vector<StageTiming>& timings, const std::string& stage, double seconds);

// Adds every stage of `more` to `total`, stage by stage.
void add_timings(std::vector<StageTiming>& total, const std::vector<StageTiming>& more);

// Adds the time from its construction to its destruction to one stage's entry.
class StageTimer {
 public:
  StageTimer(std::vector<StageTiming>& timings, std::string stage)
      : timings_(timings), stage_(std::move(stage)), start_(SteadyClock::now()) {}
  ~StageTimer() { add_timing(timings_, stage_, seconds_since(start_)); }
  StageTimer(const StageTimer&) = delete;
  StageTimer& operator=(const StageTimer&) = delete;

 private:
  std::vector<StageTiming>& timings_;
  std::string stage_;
  SteadyClock::time_point start_;
};

// Runs named stages, each timed into `timings` and reported to the progress callback (0 then 1).
class StageRunner {
 public:
  StageRunner(std::vector<StageTiming>& timings, const ProgressCallback& progress)
      : timings_(timings), progress_(progress) {}
  template <typename F>
  auto run(const std::string& stage, F&& f) {
    if (progress_) progress_(stage, 0.0);
    auto value = [&] {
      const StageTimer timer(timings_, stage);
      return f();
    }();
    if (progress_) progress_(stage, 1.0);
    return value;
  }

 private:
  std::vector<StageTiming>& timings_;
  const ProgressCallback& progress_;
};

}  // namespace k4reg
