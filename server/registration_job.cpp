#include "registration_job.h"

#include <algorithm>
#include <chrono>

#include "k4reg/io/cloud_io.h"
#include "k4reg/util/error.h"

namespace k4reg::service {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

}  // namespace

PointCloud load_cloud(const CloudSource& source, const ReadOptions& options) {
  try {
    if (source.file.empty()) return read_cloud_bytes(source.bytes, source.name, options);
    return read_cloud(source.file, options);
  } catch (const Error& e) {
    std::string message = e.what();
    if (!source.file.empty() && message.rfind(source.file, 0) == 0)
      message = source.name + message.substr(source.file.size());
    if (e.code() == ErrorCode::kResourceExhausted) message += " (--max-points)";
    throw Error(e.code(), message);
  }
}

void StageTracker::operator()(const std::string& stage, double fraction) {
  if (!listener_) return;
  if (stage != stage_) {
    stage_ = stage;
    finished_ = false;
    listener_(stage, v1::StageEvent::PHASE_STARTED, 0.0);
    if (fraction <= 0.0) return;
  }
  if (finished_) return;
  finished_ = fraction >= 1.0;
  listener_(stage, finished_ ? v1::StageEvent::PHASE_FINISHED : v1::StageEvent::PHASE_PROGRESS,
            std::clamp(fraction, 0.0, 1.0));
}

std::optional<CloudPreview> preview_stage(std::size_t preview_points, StageTracker& progress,
                                          const std::function<CloudPreview(const PreviewParams&)>& make) {
  if (preview_points == 0) return std::nullopt;
  progress("preview", 0.0);
  PreviewParams params;
  params.max_points = preview_points;
  CloudPreview preview = make(params);
  progress("preview", 1.0);
  return preview;
}

RegistrationOutcome run_registration(const CloudSource& source, const CloudSource& target, RegistrationParams params,
                                     std::size_t preview_points, const JobLimits& limits, MemoryBudget& memory,
                                     const CancellationToken& token, const StageListener& listener, JobReport& report) {
  token.throw_if_stopped();  // cancelled or expired while queued
  StageTracker progress(listener);

  const auto load_start = Clock::now();
  progress("load", 0.0);
  const ReadOptions options{limits.max_points};
  const PointCloud source_cloud = load_cloud(source, options);
  report.source_points = source_cloud.size();
  token.throw_if_stopped();
  const PointCloud target_cloud = load_cloud(target, options);
  report.target_points = target_cloud.size();
  progress("load", 1.0);
  report.load_s = seconds_since(load_start);

  const MemoryBudget::Reservation reservation =
      memory.reserve(kBytesPerPoint * (source_cloud.size() + target_cloud.size()), token);

  if (params.threads == 0 || params.threads > limits.job_threads) params.threads = limits.job_threads;
  const auto start = Clock::now();
  const ProgressCallback callback = [&](const std::string& stage, double fraction) { progress(stage, fraction); };
  RegistrationOutcome outcome{register_clouds(source_cloud, target_cloud, params, &token, callback), std::nullopt};
  report.registration_s = seconds_since(start);
  outcome.preview = preview_stage(preview_points, progress, [&](const PreviewParams& preview) {
    return make_pair_preview(source_cloud, target_cloud, outcome.result, preview, &token);
  });
  return outcome;
}

}  // namespace k4reg::service
