// The service's metrics, one registry for the gRPC and the HTTP API, rendered in the Prometheus text
// exposition format 0.0.4 (GET /metrics). Hand-written: Debian 12 packages no Prometheus client library.
// Thread-safe; one instance, owned by main() and reached through ServiceContext (no global registry).
//
// Names follow the Prometheus conventions (k4reg_ prefix, base units, counters end in _total); labels have
// bounded values only (protocol, route or RPC method, status code name, refusal reason), never request ids
// or file names.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <mutex>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace k4reg::service {

// Fixed-bucket histogram; not synchronised (Metrics holds the lock).
class Histogram {
 public:
  explicit Histogram(std::span<const double> upper_bounds);
  void observe(double value);
  // Appends the _bucket, _sum and _count lines; `labels` is the rendered label set without braces ("" = none).
  void render(std::string& out, std::string_view name, std::string_view labels) const;

 private:
  std::span<const double> upper_bounds_;
  std::vector<std::uint64_t> counts_;  // per bucket, not cumulative
  double sum_ = 0;
  std::uint64_t count_ = 0;
};

class Metrics {
 public:
  explicit Metrics(std::string version);

  // A call ended, whatever the protocol ("grpc", "http"): `method` is the RPC method or the HTTP route
  // ("POST /v1/register"), `code` the status code name ("OK", "RESOURCE_EXHAUSTED", ...).
  void observe_request(std::string_view protocol, std::string_view method, std::string_view code, double seconds,
                       std::uint64_t upload_bytes);
  // A job ended on a worker after waiting `queue_wait_s` and running `run_s`; `points` were loaded.
  void observe_job(double queue_wait_s, double run_s, std::uint64_t points);
  // A job was stopped by its cancellation token (client cancel, deadline, time budget, drain) or taken out
  // of the queue before it ran.
  void job_cancelled();
  // The queue refused a job: `reason` is "queue_full" or "draining".
  void job_rejected(std::string_view reason);

  // k4reg-server --peers, on the coordinator: a pair job of `bytes` was sent to `peer` (its address); a call to it did not
  // give the pair's outcome (`code`) and the pair is tried again; no peer registered a pair and it ran here
  // (`reason`: "peers_failed" or "too_large").
  void peer_pair_sent(std::string_view peer, std::uint64_t bytes);
  void peer_pair_retried(std::string_view peer, std::string_view code);
  void peer_pair_failed(std::string_view reason);
  // On a peer: a RegisterPair call ended with `code`.
  void pair_job_received(std::string_view code);

  // Gauges read from the queue and the memory budget when scraped.
  struct Snapshot {
    std::size_t queue_depth = 0, queue_capacity = 0, workers_busy = 0, workers = 0;
    std::size_t pair_queue_depth = 0, pair_workers_busy = 0, pair_workers = 0;  // RegisterPair jobs
    std::size_t pair_cache_bytes = 0;  // their scans kept (scan_cache.h)
    std::size_t memory_reserved_bytes = 0;
  };
  std::string exposition(const Snapshot& snapshot) const;

 private:
  const std::string version_;
  mutable std::mutex mutex_;
  std::map<std::string, double> requests_;            // rendered labels -> count
  std::map<std::string, Histogram> request_seconds_;  // rendered labels -> latency
  std::map<std::string, double> upload_bytes_;        // rendered labels -> bytes
  std::map<std::string, double> rejected_;            // rendered labels -> count
  std::map<std::string, double> peer_sent_, peer_sent_bytes_, peer_retried_, peer_failed_, pairs_received_;  // by labels
  Histogram job_seconds_, queue_wait_seconds_;
  double points_ = 0, cancelled_ = 0;
  const double start_time_s_;  // since the Unix epoch
};

// The content type of Metrics::exposition().
inline constexpr const char* kPrometheusContentType = "text/plain; version=0.0.4; charset=utf-8";

}  // namespace k4reg::service
