// How busy the machine is apart from the benchmark's own runs. The machine is shared (builds, test runs,
// other benchmarks), and a run that competed for the cores would report a wrong time, so the orchestrator
// waits for quiet before a run and repeats a run during which others used the CPU.
// Reads /proc/stat (all CPUs, busy = user + nice + system + irq + softirq + steal); costs microseconds.
#pragma once

namespace k4reg::bench {

// CPU seconds the whole machine has been busy since boot.
double machine_busy_cpu_s();

struct QuietWait {
  double waited_s = 0.0;
  bool quiet = true;  // false: still busy when max_wait_s ran out
};

// Blocks until the machine uses less than max_busy_cores over a few seconds, or max_wait_s passes.
QuietWait wait_until_quiet(double max_busy_cores, double max_wait_s);

}  // namespace k4reg::bench
