#include "jobs/registration_job.h"

#include <algorithm>

#include <fmt/format.h>

#include "jobs/cloud_bytes.h"
#include "k4reg/io/cloud_io.h"
#include "k4reg/io/declared_points.h"
#include "k4reg/util/error.h"
#include "k4reg/util/stopwatch.h"

namespace k4reg::service {
namespace {

}  // namespace

void JobLimits::check_project_scans(std::size_t scans) const {
  if (scans > max_project_scans)
    fail(ErrorCode::kResourceExhausted,
         fmt::format("a project of more than {} scans (--max-project-scans)", max_project_scans));
}

void JobLimits::check_project_points(std::uint64_t points) const {
  if (points > max_project_points)
    fail(ErrorCode::kResourceExhausted, fmt::format("the scans' headers declare {} points, more than the {} a project "
                                                    "may have (--max-project-points)", points, max_project_points));
}

namespace {

// The readers name the file as given (the client's name); a count over ReadOptions::max_points gets its flag.
template <typename Read>
auto read_naming_the_limit(const Read& read) {
  try {
    return read();
  } catch (const Error& e) {
    if (e.code() != ErrorCode::kResourceExhausted) throw;
    throw Error(e.code(), std::string(e.what()) + " (--max-points)");
  }
}

}  // namespace

std::uint64_t declared_cloud_points(const CloudSource& source, std::string_view bytes, const ReadOptions& options) {
  return read_naming_the_limit([&] { return declared_points(bytes, source.name, options); });
}

PointCloud load_cloud(const CloudSource& source, std::string_view bytes, const ReadOptions& options) {
  return read_naming_the_limit([&] { return read_cloud_bytes(bytes, source.name, options); });
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

RegistrationOutcome run_registration(const PairJob& pair, const JobLimits& limits, MemoryBudget& memory,
                                     const CancellationToken& token, const StageListener& listener, JobReport& report) {
  const CloudSource &source = pair.source, &target = pair.target;
  token.throw_if_stopped();  // cancelled or expired while queued
  StageTracker progress(listener);

  const auto load_start = SteadyClock::now();
  progress("load", 0.0);
  const ReadOptions options{limits.max_points};
  const CloudBytes source_bytes(source), target_bytes(target);
  // Reserved before decoding: a small file can declare (and decode to) far more than its size.
  const std::uint64_t declared = declared_cloud_points(source, source_bytes.bytes(), options) +
                                 declared_cloud_points(target, target_bytes.bytes(), options);
  const MemoryBudget::Reservation reservation = memory.reserve(kBytesPerPoint * declared, token);
  const PointCloud source_cloud = load_cloud(source, source_bytes.bytes(), options);
  report.source_points = source_cloud.size();
  token.throw_if_stopped();
  const PointCloud target_cloud = load_cloud(target, target_bytes.bytes(), options);
  report.target_points = target_cloud.size();
  progress("load", 1.0);
  report.load_s = seconds_since(load_start);

  RegistrationParams params = pair.params;
  if (params.threads == 0 || params.threads > limits.job_threads) params.threads = limits.job_threads;
  const auto start = SteadyClock::now();
  const ProgressCallback callback = [&](const std::string& stage, double fraction) { progress(stage, fraction); };
  RegistrationOutcome outcome{register_clouds(source_cloud, target_cloud, params, &token, callback), std::nullopt};
  report.registration_s = seconds_since(start);
  outcome.preview = preview_stage(pair.preview_points, progress, [&](const PreviewParams& preview) {
    return make_pair_preview(source_cloud, target_cloud, outcome.result, preview, &token);
  });
  return outcome;
}

}  // namespace k4reg::service
