// Runs a command as a child process with a hard wall-time limit and collects its standard output and
// its own peak resident set size (getrusage of that child only).
#pragma once

#include <string>
#include <vector>

namespace k4reg::bench {

struct ChildOutcome {
  int exit_code = -1;       // -1 when killed by a signal
  int signal = 0;           // the signal that killed it, or 0
  bool timed_out = false;   // killed after the time limit
  std::string output;       // everything the child wrote to stdout
  double peak_rss_mb = 0.0;
  double wall_s = 0.0;
  double cpu_s = 0.0;       // user + system time of the child and its threads
};

// argv[0] must be a path. stderr is inherited. Throws std::runtime_error when the process cannot start.
ChildOutcome run_child(const std::vector<std::string>& argv, double time_limit_s);

}  // namespace k4reg::bench
