// Summary statistics of benchmark samples; an empty sample gives NaN (shown as "–" in the tables).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace k4reg::bench {

inline constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

// Linear interpolation between the closest ranks (numpy's default), fraction in [0, 1].
inline double percentile(std::vector<double> v, double fraction) {
  if (v.empty()) return kNan;
  std::sort(v.begin(), v.end());
  const double rank = fraction * static_cast<double>(v.size() - 1);
  const std::size_t below = static_cast<std::size_t>(std::floor(rank));
  const std::size_t above = std::min(below + 1, v.size() - 1);
  return v[below] + (rank - static_cast<double>(below)) * (v[above] - v[below]);
}

inline double median(std::vector<double> v) { return percentile(std::move(v), 0.5); }

inline double minimum(const std::vector<double>& v) { return v.empty() ? kNan : *std::min_element(v.begin(), v.end()); }
inline double maximum(const std::vector<double>& v) { return v.empty() ? kNan : *std::max_element(v.begin(), v.end()); }

inline double mean(const std::vector<double>& v) {
  if (v.empty()) return kNan;
  double sum = 0;
  for (double x : v) sum += x;
  return sum / static_cast<double>(v.size());
}

}  // namespace k4reg::bench
