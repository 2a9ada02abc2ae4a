// Cells of the benchmark tables in bench/RESULTS.md; NaN (an empty sample) is shown as "–".
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <string>

namespace k4reg::bench {

inline std::string fmt(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, value);
  return buffer;
}

inline std::string size_label(std::size_t points) { return points == 0 ? "–" : fmt("%.1fM", points / 1e6); }

inline std::string sigma_label(double sigma_m) {
  return sigma_m < 1.0 ? fmt("%g mm", sigma_m * 1000.0) : fmt("%g m", sigma_m);
}

inline std::string percent(double fraction) { return std::isnan(fraction) ? "–" : fmt("%.0f %%", 100.0 * fraction); }

inline std::string number(double value, const char* format) { return std::isnan(value) ? "–" : fmt(format, value); }

// Lengths in metres, with enough digits for the bunny's millimetres.
inline std::string metres(double value) {
  if (std::isnan(value)) return "–";
  return value < 0.01 ? fmt("%.4f", value) : value < 1.0 ? fmt("%.3f", value) : fmt("%.2f", value);
}

inline std::string seconds(double value) {
  if (std::isnan(value)) return "–";
  return value < 10 ? fmt("%.2f", value) : value < 100 ? fmt("%.1f", value) : fmt("%.0f", value);
}

// Elapsed time as h:mm:ss, for progress lines.
inline std::string clock_text(double seconds) {
  const int s = static_cast<int>(seconds);
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%d:%02d:%02d", s / 3600, s / 60 % 60, s % 60);
  return buffer;
}

}  // namespace k4reg::bench
