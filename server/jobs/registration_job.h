// What a worker does for one request, whatever RPC it came from: reserve the memory both clouds' headers declare,
// load them, run the core. Shared by the unary and the streaming reactor (and the HTTP API later).
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "k4reg/io/cloud_io.h"
#include "k4reg/qa/cloud_preview.h"
#include "k4reg/util/cancellation.h"
#include "k4reg/registration/registration.h"
#include "k4reg/v1/registration.pb.h"
#include "jobs/memory_budget.h"

namespace k4reg::service {

class PathPolicy;

// A cloud as the worker reads it: a file (a resolved data-root path or a spool file) or inline bytes.
struct CloudSource {
  std::string name;        // as the client named it: used in messages and as the format hint
  std::string file;        // empty = read `bytes`
  std::string_view bytes;  // owned by the request, which outlives the job
  const PathPolicy* paths = nullptr;  // set for a data-root file: opened through it (PathPolicy::open)
};

struct JobLimits {
  std::size_t max_points = 0;                    // per cloud, 0 = unlimited
  int job_threads = 1;                           // core threads per job; the request may ask for fewer
  std::size_t max_project_scans = 500;           // --max-project-scans
  std::uint64_t max_project_points = 500'000'000;  // --max-project-points: all scans, as their headers declare

  // Throw k4reg::Error(kResourceExhausted) naming the limit and its flag.
  void check_project_scans(std::size_t scans) const;
  void check_project_points(std::uint64_t points) const;
};

// Filled as the job goes, so that a failed job still reports what it got to.
struct JobReport {
  std::uint64_t source_points = 0, target_points = 0;
  double load_s = 0, registration_s = 0;
};

// Stage events for progress streams: "load", then the core's stages. Called on the worker thread.
using StageListener = std::function<void(const std::string& stage, v1::StageEvent::Phase phase, double fraction)>;

// The core reports (stage, fraction) with 0 at a stage's start and 1 at its end (a stage may report 1
// twice); listeners get explicit phases.
class StageTracker {
 public:
  explicit StageTracker(const StageListener& listener) : listener_(listener) {}
  void operator()(const std::string& stage, double fraction);

 private:
  const StageListener& listener_;
  std::string stage_;
  bool finished_ = false;
};

// The preview as a job's last stage ("preview"): `make` with preview_points, or none when that is 0.
std::optional<CloudPreview> preview_stage(std::size_t preview_points, StageTracker& progress,
                                          const std::function<CloudPreview(const PreviewParams&)>& make);

// The points the cloud's header declares (declared_points.h), nothing decoded yet; then the cloud itself, from the
// same bytes (CloudBytes). Error messages name it as the client did (never a server path). Throw k4reg::Error.
std::uint64_t declared_cloud_points(const CloudSource& source, std::string_view bytes, const ReadOptions& options);
PointCloud load_cloud(const CloudSource& source, std::string_view bytes, const ReadOptions& options);

// What a pair job answers: the result and, when asked for (preview_points > 0), the preview.
struct RegistrationOutcome {
  RegistrationResult result;
  std::optional<CloudPreview> preview;
};

// A pair call's inputs as the gRPC and HTTP front ends resolve them (cf. ProjectJob).
struct PairJob {
  CloudSource source, target;
  RegistrationParams params;
  std::size_t preview_points = 0;  // > 0: a preview of that many points comes back too
};

// Throws k4reg::Error (kCancelled / kDeadlineExceeded once the token fires). The preview is the last stage
// ("preview").
RegistrationOutcome run_registration(const PairJob& pair, const JobLimits& limits, MemoryBudget& memory,
                                     const CancellationToken& token, const StageListener& listener, JobReport& report);

}  // namespace k4reg::service
