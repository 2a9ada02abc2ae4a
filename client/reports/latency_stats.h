// Latency figures of a load run, as ghz reports them: min, mean, percentiles, max and a histogram.
#pragma once

#include <cstddef>
#include <vector>

namespace k4reg::cli {

struct LatencySummary {
  std::size_t count = 0;
  double min = 0, mean = 0, p50 = 0, p90 = 0, p95 = 0, p99 = 0, max = 0;  // all 0 without samples
};

// Nearest rank: the smallest sample with at least p % of the samples at or below it (so always a measured
// value, never an interpolation). `sorted` ascending and non-empty; p in [0, 100].
double percentile(const std::vector<double>& sorted, double p);

LatencySummary summarize(std::vector<double> samples);

struct HistogramBucket {
  double lower = 0, upper = 0;  // [lower, upper); the last bucket includes its upper bound (the maximum)
  std::size_t count = 0;
};

// `buckets` equal-width buckets from the minimum to the maximum (one bucket when all samples are equal,
// none without samples).
std::vector<HistogramBucket> histogram(const std::vector<double>& samples, std::size_t buckets);

}  // namespace k4reg::cli
