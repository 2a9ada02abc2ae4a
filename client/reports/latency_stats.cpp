#include "reports/latency_stats.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace k4reg::cli {

double percentile(const std::vector<double>& sorted, double p) {
  const double rank = std::ceil(p / 100.0 * static_cast<double>(sorted.size()));
  const std::size_t index = static_cast<std::size_t>(std::clamp(rank, 1.0, static_cast<double>(sorted.size()))) - 1;
  return sorted[index];
}

LatencySummary summarize(std::vector<double> samples) {
  LatencySummary s;
  if (samples.empty()) return s;
  std::sort(samples.begin(), samples.end());
  s.count = samples.size();
  s.min = samples.front();
  s.max = samples.back();
  s.mean = std::accumulate(samples.begin(), samples.end(), 0.0) / static_cast<double>(samples.size());
  s.p50 = percentile(samples, 50);
  s.p90 = percentile(samples, 90);
  s.p95 = percentile(samples, 95);
  s.p99 = percentile(samples, 99);
  return s;
}

std::vector<HistogramBucket> histogram(const std::vector<double>& samples, std::size_t buckets) {
  if (samples.empty() || buckets == 0) return {};
  const auto [min_it, max_it] = std::minmax_element(samples.begin(), samples.end());
  const double min = *min_it, max = *max_it;
  if (max == min) return {{min, max, samples.size()}};
  const double width = (max - min) / static_cast<double>(buckets);
  std::vector<HistogramBucket> result(buckets);
  for (std::size_t b = 0; b < buckets; ++b) {
    result[b].lower = min + width * static_cast<double>(b);
    result[b].upper = b + 1 == buckets ? max : min + width * static_cast<double>(b + 1);
  }
  for (double sample : samples) ++result[std::min(static_cast<std::size_t>((sample - min) / width), buckets - 1)].count;
  return result;
}

}  // namespace k4reg::cli
