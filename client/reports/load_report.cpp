#include "reports/load_report.h"

#include <fmt/format.h>

#include <algorithm>

#include "remote/server_timings.h"
#include "reports/status_text.h"

namespace k4reg::cli {
namespace {

constexpr std::size_t kHistogramBuckets = 10;
constexpr std::size_t kBarWidth = 40;

nlohmann::json summary_to_json(const LatencySummary& s) {
  return {{"count", s.count}, {"min", s.min}, {"mean", s.mean}, {"p50", s.p50},
          {"p90", s.p90},     {"p95", s.p95}, {"p99", s.p99},   {"max", s.max}};
}

std::string mode(const LoadPlan& plan) {
  return plan.rate > 0 ? fmt::format("open loop, {:g} calls/s", plan.rate)
                       : fmt::format("closed loop, concurrency {}", plan.concurrency);
}

}  // namespace

LoadSummary summarize_load(const LoadOutcome& outcome) {
  LoadSummary s;
  s.calls = outcome.calls.size();
  s.wall_s = outcome.wall_s;
  s.calls_per_s = outcome.wall_s > 0 ? static_cast<double>(s.calls) / outcome.wall_s : 0;
  s.client_cpu_percent = outcome.wall_s > 0 ? 100.0 * outcome.cpu_s / outcome.wall_s : 0;
  std::vector<double> latency, queue_wait, to_job_start, registration, to_reply, overhead;
  for (const CallRecord& call : outcome.calls) {
    ++s.status_counts[status_code_name(call.code)];
    if (call.code != grpc::StatusCode::OK) continue;
    latency.push_back(call.latency_s);
    if (call.timings) {
      queue_wait.push_back(call.timings->queue_wait_s());
      to_job_start.push_back(call.timings->request_to_job_start_s());
      registration.push_back(call.timings->registration_s());
      to_reply.push_back(call.timings->job_end_to_reply_s());
      overhead.push_back(server_overhead_s(*call.timings));
    }
    ++s.replies_per_server[call.server_id];
  }
  s.histogram = histogram(latency, kHistogramBuckets);
  s.latency_s = summarize(std::move(latency));
  s.queue_wait_s = summarize(std::move(queue_wait));
  s.request_to_job_start_s = summarize(std::move(to_job_start));
  s.registration_s = summarize(std::move(registration));
  s.job_end_to_reply_s = summarize(std::move(to_reply));
  s.overhead_s = summarize(std::move(overhead));
  return s;
}

nlohmann::json load_summary_to_json(const LoadPlan& plan, const LoadSummary& s) {
  nlohmann::json histogram = nlohmann::json::array();
  for (const HistogramBucket& b : s.histogram)
    histogram.push_back({{"lower_s", b.lower}, {"upper_s", b.upper}, {"count", b.count}});
  return {{"mode", plan.rate > 0 ? "open" : "closed"},
          {"concurrency", plan.concurrency},
          {"rate", plan.rate},
          {"calls", s.calls},
          {"wall_s", s.wall_s},
          {"calls_per_s", s.calls_per_s},
          {"client_cpu_percent", s.client_cpu_percent},
          {"latency_s", summary_to_json(s.latency_s)},
          {"histogram", histogram},
          {"status_counts", s.status_counts},
          {"server_timings_s",
           {{"queue_wait", summary_to_json(s.queue_wait_s)},
            {"request_to_job_start", summary_to_json(s.request_to_job_start_s)},
            {"registration", summary_to_json(s.registration_s)},
            {"job_end_to_reply", summary_to_json(s.job_end_to_reply_s)},
            {"overhead", summary_to_json(s.overhead_s)}}},
          {"replies_per_server", s.replies_per_server}};
}

void print_load_summary(std::ostream& out, const LoadPlan& plan, const LoadSummary& s) {
  out << fmt::format("Summary ({}):\n", mode(plan));
  out << fmt::format("  {:<16}{}\n", "calls", s.calls);
  out << fmt::format("  {:<16}{:.2f} s\n", "total", s.wall_s);
  out << fmt::format("  {:<16}{:.2f}\n", "calls/s", s.calls_per_s);
  out << fmt::format("  {:<16}{:.1f} % of one core\n", "client CPU", s.client_cpu_percent);

  out << "\nStatus codes:\n";
  for (const auto& [code, count] : s.status_counts) out << fmt::format("  {:<22}{}\n", code, count);

  if (s.latency_s.count == 0) return;  // nothing but zeros to show
  const LatencySummary& l = s.latency_s;
  out << fmt::format("\nLatency of the {} OK calls:\n", l.count);
  for (const auto& [name, value] : {std::pair{"min", l.min},
                                    {"mean", l.mean},
                                    {"p50", l.p50},
                                    {"p90", l.p90},
                                    {"p95", l.p95},
                                    {"p99", l.p99},
                                    {"max", l.max}})
    out << fmt::format("  {:<16}{:.1f} ms\n", name, 1000.0 * value);

  if (!s.histogram.empty()) {
    out << "\nLatency histogram (upper bound, calls):\n";
    std::size_t most = 0;
    for (const HistogramBucket& b : s.histogram) most = std::max(most, b.count);
    for (const HistogramBucket& b : s.histogram)
      out << fmt::format("  {:>10.1f} ms [{:>5}] |{}\n", 1000.0 * b.upper, b.count,
                         std::string(most ? b.count * kBarWidth / most : 0, '#'));
  }

  out << fmt::format("\nServer timings of the OK calls:  {:>10} {:>10}\n", "p50", "p99");
  for (const auto& [name, t] : {std::pair<const char*, const LatencySummary&>{"queue wait", s.queue_wait_s},
                                {"request to job start", s.request_to_job_start_s},
        {"registration", s.registration_s},
                                {"job end to reply", s.job_end_to_reply_s},
                                {"overhead", s.overhead_s}})
    out << fmt::format("  {:<31}{:>7.2f} ms {:>7.2f} ms\n", name, 1000.0 * t.p50, 1000.0 * t.p99);
  out << "  (overhead: request to job start without queue wait and upload, plus job end to reply)\n";

  if (!s.replies_per_server.empty()) {
    out << "\nOK calls per server:\n";
    for (const auto& [server, count] : s.replies_per_server) out << fmt::format("  {:<30}{}\n", server, count);
  }
}

}  // namespace k4reg::cli
