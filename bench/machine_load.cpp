#include "machine_load.h"

#include <unistd.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

namespace k4reg::bench {

double machine_busy_cpu_s() {
  std::ifstream in("/proc/stat");
  std::string line;
  std::getline(in, line);  // "cpu  user nice system idle iowait irq softirq steal guest guest_nice"
  std::istringstream fields(line.substr(3));
  double user = 0, nice = 0, system = 0, idle = 0, iowait = 0, irq = 0, softirq = 0, steal = 0;
  fields >> user >> nice >> system >> idle >> iowait >> irq >> softirq >> steal;
  return (user + nice + system + irq + softirq + steal) / static_cast<double>(sysconf(_SC_CLK_TCK));
}

QuietWait wait_until_quiet(double max_busy_cores, double max_wait_s) {
  constexpr double kSample_s = 3.0, kPause_s = 15.0;
  const auto start = std::chrono::steady_clock::now();
  const auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  QuietWait wait;
  for (;;) {
    const double busy = machine_busy_cpu_s();
    std::this_thread::sleep_for(std::chrono::duration<double>(kSample_s));
    if ((machine_busy_cpu_s() - busy) / kSample_s < max_busy_cores) break;
    if (elapsed() > max_wait_s) {
      wait.quiet = false;
      break;
    }
    std::this_thread::sleep_for(std::chrono::duration<double>(kPause_s));
  }
  wait.waited_s = elapsed();
  return wait;
}

}  // namespace k4reg::bench
