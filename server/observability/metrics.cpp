#include "observability/metrics.h"

#include <fmt/format.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>

namespace k4reg::service {
namespace {

// Seconds. Requests span probes (~1 ms) to long registrations; jobs span quick pairs to half-hour scans.
constexpr std::array kRequestBuckets{0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1.0, 2.5, 5.0, 10.0, 30.0, 60.0, 120.0, 300.0};
constexpr std::array kJobBuckets{0.1, 0.25, 0.5, 1.0, 2.5, 5.0, 10.0, 30.0, 60.0, 120.0, 300.0, 600.0, 1800.0};
constexpr std::array kQueueWaitBuckets{0.001, 0.01, 0.1, 0.5, 1.0, 5.0, 10.0, 30.0, 60.0, 300.0};

// Label values escape backslash, double quote and newline.
std::string escape_label(std::string_view value) {
  std::string escaped;
  for (const char c : value) {
    if (c == '\\' || c == '"') escaped += '\\';
    if (c == '\n') {
      escaped += "\\n";
      continue;
    }
    escaped += c;
  }
  return escaped;
}

std::string labels(std::initializer_list<std::pair<std::string_view, std::string_view>> pairs) {
  std::string text;
  for (const auto& [name, value] : pairs) {
    if (!text.empty()) text += ',';
    fmt::format_to(std::back_inserter(text), "{}=\"{}\"", name, escape_label(value));
  }
  return text;
}

void header(std::string& out, std::string_view name, std::string_view type, std::string_view help) {
  fmt::format_to(std::back_inserter(out), "# HELP {} {}\n# TYPE {} {}\n", name, help, name, type);
}

void sample(std::string& out, std::string_view name, std::string_view label_text, double value) {
  if (label_text.empty())
    fmt::format_to(std::back_inserter(out), "{} {}\n", name, value);
  else
    fmt::format_to(std::back_inserter(out), "{}{{{}}} {}\n", name, label_text, value);
}

void metric(std::string& out, std::string_view name, std::string_view type, std::string_view help, double value) {
  header(out, name, type, help);
  sample(out, name, "", value);
}

void family(std::string& out, std::string_view name, std::string_view type, std::string_view help,
            const std::map<std::string, double>& series) {
  header(out, name, type, help);
  for (const auto& [label_text, value] : series) sample(out, name, label_text, value);
}

// The standard process metrics every Prometheus client library exports (from /proc and getrusage).
void process_metrics(std::string& out, double start_time_s) {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  const double cpu_s = double(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
                       double(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) * 1e-6;
  metric(out, "process_cpu_seconds_total", "counter", "User and system CPU time spent in seconds.", cpu_s);
  std::size_t pages = 0, resident_pages = 0;
  std::ifstream("/proc/self/statm") >> pages >> resident_pages;
  metric(out, "process_resident_memory_bytes", "gauge", "Resident memory size in bytes.",
         double(resident_pages) * double(sysconf(_SC_PAGESIZE)));
  std::error_code ec;
  const auto fds = std::distance(std::filesystem::directory_iterator("/proc/self/fd", ec),
                                 std::filesystem::directory_iterator());
  metric(out, "process_open_fds", "gauge", "Number of open file descriptors.", double(fds));
  metric(out, "process_start_time_seconds", "gauge", "Start time of the process since unix epoch in seconds.",
         start_time_s);
}

double now_since_epoch_s() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

}  // namespace

Histogram::Histogram(std::span<const double> upper_bounds)
    : upper_bounds_(upper_bounds), counts_(upper_bounds.size() + 1, 0) {}

void Histogram::observe(double value) {
  const auto bucket = std::lower_bound(upper_bounds_.begin(), upper_bounds_.end(), value) - upper_bounds_.begin();
  ++counts_[static_cast<std::size_t>(bucket)];  // the last slot is +Inf
  sum_ += value;
  ++count_;
}

void Histogram::render(std::string& out, std::string_view name, std::string_view label_text) const {
  const std::string prefix = label_text.empty() ? std::string() : std::string(label_text) + ",";
  const std::string bucket_name = std::string(name) + "_bucket";
  std::uint64_t cumulative = 0;
  for (std::size_t i = 0; i < upper_bounds_.size(); ++i) {
    cumulative += counts_[i];
    sample(out, bucket_name, fmt::format("{}le=\"{}\"", prefix, upper_bounds_[i]), double(cumulative));
  }
  sample(out, bucket_name, prefix + "le=\"+Inf\"", double(count_));
  sample(out, std::string(name) + "_sum", label_text, sum_);
  sample(out, std::string(name) + "_count", label_text, double(count_));
}

Metrics::Metrics(std::string version)
    : version_(std::move(version)),
      job_seconds_(kJobBuckets),
      queue_wait_seconds_(kQueueWaitBuckets),
      start_time_s_(now_since_epoch_s()) {}

void Metrics::observe_request(std::string_view protocol, std::string_view method, std::string_view code,
                              double seconds, std::uint64_t upload_bytes) {
  const std::string route = labels({{"protocol", protocol}, {"method", method}});
  std::lock_guard lock(mutex_);
  requests_[labels({{"protocol", protocol}, {"method", method}, {"code", code}})] += 1;
  request_seconds_.try_emplace(route, kRequestBuckets).first->second.observe(seconds);
  if (upload_bytes > 0) upload_bytes_[labels({{"protocol", protocol}})] += double(upload_bytes);
}

void Metrics::observe_job(double queue_wait_s, double run_s, std::uint64_t points) {
  std::lock_guard lock(mutex_);
  queue_wait_seconds_.observe(queue_wait_s);
  job_seconds_.observe(run_s);
  points_ += double(points);
}

void Metrics::job_cancelled() {
  std::lock_guard lock(mutex_);
  cancelled_ += 1;
}

void Metrics::job_rejected(std::string_view reason) {
  std::lock_guard lock(mutex_);
  rejected_[labels({{"reason", reason}})] += 1;
}

void Metrics::peer_pair_sent(std::string_view peer, std::uint64_t bytes) {
  std::lock_guard lock(mutex_);
  peer_sent_[labels({{"peer", peer}})] += 1;
  peer_sent_bytes_[labels({{"peer", peer}})] += double(bytes);
}

void Metrics::peer_pair_retried(std::string_view peer, std::string_view code) {
  std::lock_guard lock(mutex_);
  peer_retried_[labels({{"peer", peer}, {"code", code}})] += 1;
}

void Metrics::peer_pair_failed(std::string_view reason) {
  std::lock_guard lock(mutex_);
  peer_failed_[labels({{"reason", reason}})] += 1;
}

void Metrics::pair_job_received(std::string_view code) {
  std::lock_guard lock(mutex_);
  pairs_received_[labels({{"code", code}})] += 1;
}

std::string Metrics::exposition(const Snapshot& s) const {
  std::string out;
  header(out, "k4reg_build_info", "gauge", "Build of the k4reg server (always 1).");
  sample(out, "k4reg_build_info", labels({{"version", version_}}), 1);
  {
    std::lock_guard lock(mutex_);
    family(out, "k4reg_requests_total", "counter", "Calls ended, by protocol, method (RPC or route) and status code.",
           requests_);
    header(out, "k4reg_request_duration_seconds", "histogram", "Call latency from arrival to reply, by protocol and method.");
    for (const auto& [label_text, histogram] : request_seconds_)
      histogram.render(out, "k4reg_request_duration_seconds", label_text);
    header(out, "k4reg_job_duration_seconds", "histogram", "Time a job ran on a worker (loading and registration).");
    job_seconds_.render(out, "k4reg_job_duration_seconds", "");
    header(out, "k4reg_job_queue_wait_seconds", "histogram", "Time a job waited in the queue for a worker.");
    queue_wait_seconds_.render(out, "k4reg_job_queue_wait_seconds", "");
    metric(out, "k4reg_points_processed_total", "counter", "Points loaded by jobs (source and target).", points_);
    family(out, "k4reg_upload_bytes_total", "counter", "Bytes of uploaded clouds received, by protocol.", upload_bytes_);
    metric(out, "k4reg_jobs_cancelled_total", "counter",
           "Jobs stopped by cancellation, a deadline, the time budget or the drain, or withdrawn while queued.",
           cancelled_);
    family(out, "k4reg_jobs_rejected_total", "counter", "Jobs the queue refused, by reason (queue_full, draining).",
           rejected_);
    family(out, "k4reg_peer_pairs_sent_total", "counter", "Pair calls this coordinator made, by peer address.", peer_sent_);
    family(out, "k4reg_peer_pair_bytes_sent_total", "counter",
           "Bytes of the pair calls this coordinator made (scans a peer holds go as digests), by peer address.",
           peer_sent_bytes_);
    family(out, "k4reg_peer_pairs_retried_total", "counter",
           "Pair calls that failed and were tried again, by peer address and status code.", peer_retried_);
    family(out, "k4reg_peer_pairs_failed_total", "counter",
           "Pairs no peer registered, run by this coordinator, by reason (peers_failed, too_large).", peer_failed_);
    family(out, "k4reg_pair_jobs_received_total", "counter", "Pair jobs received from coordinators, by status code.",
           pairs_received_);
  }
  metric(out, "k4reg_queue_depth", "gauge", "Jobs waiting for a worker.", double(s.queue_depth));
  metric(out, "k4reg_queue_capacity", "gauge", "Jobs that may wait for a worker (--queue-size).", double(s.queue_capacity));
  metric(out, "k4reg_workers_busy", "gauge", "Workers running a job.", double(s.workers_busy));
  metric(out, "k4reg_workers", "gauge", "Workers (--workers).", double(s.workers));
  metric(out, "k4reg_pair_queue_depth", "gauge", "Pair jobs of other replicas' projects waiting.",
         double(s.pair_queue_depth));
  metric(out, "k4reg_pair_workers_busy", "gauge", "Pair workers running a job.", double(s.pair_workers_busy));
  metric(out, "k4reg_pair_workers", "gauge", "Pair workers (--pair-workers).", double(s.pair_workers));
  metric(out, "k4reg_pair_cache_bytes", "gauge", "Scans of pair jobs kept with their preparation (estimated bytes).",
         double(s.pair_cache_bytes));
  metric(out, "k4reg_memory_reserved_bytes", "gauge", "Estimated memory reserved by running jobs.",
         double(s.memory_reserved_bytes));
  process_metrics(out, start_time_s_);
  return out;
}

}  // namespace k4reg::service
