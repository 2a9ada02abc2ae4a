// k4reg-bench-compare: K-4PCS and plain 4PCS, k4reg against PCL 1.13, on simulated TLS scans (the
// paper's indoor lab and outdoor arch, Tables 2-4) and on the real pairs in /work/shared/data; beside them
// the feature-based peers (issue 49): PCL's FPFH + SAC-IA and Open3D 0.16's FPFH + RANSAC and FGR. Open3D's
// methods need Debian's python3-open3d (`apt-get install python3-open3d`, about 180 MB installed, so not in
// scripts/install-deps.sh); without it they are skipped and the report says so.
//
//   k4reg-bench-compare [--quick] [--suites lab,arch,real] [--only TEXT] [--trials N] [--methods A,B]
//                       [--resume [--redo M | --report-only]]
//       -> bench/results/compare-<mode>-*.csv, *.gp, the journal compare-<mode>-journal.jsonl (see
//          compare_journal.h) and the "compare-<mode>" block of bench/RESULTS.md
//   k4reg-bench-compare worker --job JSON          (one run; used by the orchestrator)
//   k4reg-bench-compare voxel-report --json FILE   (Google Benchmark JSON -> "voxel" block of RESULTS.md)
//
// The orchestrator simulates (and caches) the scans, then for every pair runs the keypoint job once and
// the methods interleaved trial by trial, each run in a fresh worker process (see compare_job.h), on a
// quiet machine (see machine_load.h).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

#include "child_process.h"
#include "compare_job.h"
#include "compare_journal.h"
#include "compare_report.h"
#include "k4reg/io/gt_pairs.h"
#include "machine_load.h"
#include "markdown_block.h"
#include "open3d_peer.h"
#include "sift_cache.h"
#include "simulated_scan_cache.h"
#include "table_format.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace k4reg::bench {
namespace {

struct Options {
  bool quick = false;
  bool resume = false;
  std::string redo;  // with --resume: methods whose journaled runs are measured again (after a core change)
  bool report_only = false;  // with --resume: write the outputs from the journal, run nothing
  int trials = -1;  // -1 = the mode's default; 0 = only the keypoint jobs (detectors and truth check)
  std::string suites = "lab,arch,real";
  std::string methods;  // comma-separated; "" = every method whose library is installed
  std::string only;
  std::string cache_dir = "build-bench/bench-cache";
  std::string results_dir = "bench/results";
  std::string markdown = "bench/results/comparison-with-pcl.md";
  std::string data_dir = "/work/shared/data";
  int memory_cap_mb = 12000;
};

// PCL's own iteration count L for an overlap (FPCSInitialAlignment::initCompute, PCL 1.13): about 45 at
// 0.8, 600 at 0.5, 1850 at 0.4.
int pcl_auto_iterations(double overlap) {
  const double first_estimate = std::log(1e-5) / std::log(1.0 - std::pow(overlap, 4.0));
  return std::max(4, static_cast<int>(first_estimate / (0.3 * overlap * 2.0)));
}

std::vector<Suite> make_suites(const Options& o) {
  const bool q = o.quick;
  const int trials = o.trials >= 0 ? o.trials : q ? 3 : 10;
  // PCL runs its own iteration count, capped: at low overlap it takes hours at these sizes.
  const auto pcl_iterations = [&](double overlap) {
    return std::min(pcl_auto_iterations(overlap), overlap >= 0.6 ? (q ? 20 : 100) : (q ? 50 : 300));
  };
  const int cap_s = q ? 30 : 600;
  // The plain-4PCS baseline runs once per pair on a few pairs at sigma = 50 mm (Tables 3 and 4): with the
  // paper's grid rule both implementations mostly run into the cap, which costs cap + slack per run (and
  // PCL's FPCS needs minutes even on the real pairs' small grids).
  const int baseline_trials = std::min(1, trials);
  std::vector<Suite> all;
  all.push_back({.name = "lab",
                 .data = "simulated 15 × 10 m room, 6 stations",
                 .pairs = q ? "0-1 (opposite corners), 0-2, 2-3 (3 is 2.5 m high)" : "all 15 station pairs",
                 .sizes = q ? std::vector<std::size_t>{700000, 2500000}
                            : std::vector<std::size_t>{700000, 2500000, 10000000},
                 .sigmas_m = q ? std::vector<double>{0.05} : std::vector<double>{0.1, 0.05, 0.025},
                 .overlap = 0.8,
                 .success_rmse_m = 0.5,
                 .trials = trials,
                 .pcl_iterations = pcl_iterations(0.8),
                 .cap_s = cap_s,
                 .baseline_size = 700000,  // Table 3 is at S = 0.7M
                 .baseline_trials = baseline_trials,
                 .baseline_sigma_m = 0.05,
                 .baseline_pairs = q ? std::vector<std::string>{"0-1", "0-2", "2-3"}  // 30 s cap
                                     : std::vector<std::string>{"0-1"}});
  all.push_back({.name = "arch",
                 .data = "simulated 100 × 100 m plaza with a Roman arch, 4 stations",
                 .pairs = q ? "0-1" : "neighbours 0-1, 1-2, 2-3, 3-0",
                 .sizes = {1500000},
                 .sigmas_m = q ? std::vector<double>{0.05} : std::vector<double>{0.1, 0.05, 0.025},
                 .overlap = 0.4,
                 .success_rmse_m = 1.0,
                 .trials = trials,
                 .pcl_iterations = pcl_iterations(0.4),
                 .cap_s = q ? 120 : cap_s,  // L = 1850 bases at overlap 0.4
                 .baseline = !q,
                 .baseline_trials = baseline_trials,
                 .baseline_sigma_m = 0.05,
                 .baseline_pairs = {"0-1"}});
  const auto real = [&](std::string name, std::string data, std::string pairs, double sigma_m, double overlap,
                        double success_rmse_m, std::vector<std::string> baseline_pairs = {}) {
    return Suite{.name = std::move(name),
                 .data = std::move(data),
                 .pairs = std::move(pairs),
                 .sigmas_m = {sigma_m},
                 .overlap = overlap,
                 .success_rmse_m = success_rmse_m,
                 .trials = trials,
                 .pcl_iterations = pcl_iterations(overlap),
                 .cap_s = cap_s,
                 .baseline = !q,
                 .baseline_trials = baseline_trials,
                 .baseline_pairs = std::move(baseline_pairs)};
  };
  // PCL's FPCS passes the 10-minute cap even on the bunny's ~130-point grids: the baseline takes the two
  // highest-overlap pairs only.
  all.push_back(real("bunny", "Stanford bunny range scans", "the 10 highest-overlap pairs (0.56-0.91)", 0.001, 0.7,
                     0.005, {"bun045->bun000", "ear_back->bun180"}));
  all.push_back(real("kurt3d", "3DTK Kurt3D indoor scans (cm → m; ranges > 32 m dropped)", "scan001 → scan000", 0.05,
                     0.8, 0.1));
  all.push_back(real("velodyne", "Velodyne HDL-32 consecutive scans", "251371071 → 251370668", 0.1, 0.8, 1.0));
  all.push_back(real("3dmatch", "3DMatch RGB-D fragments (GeoTransformer demo)", "src → ref", 0.025, 0.5, 0.2));
  // PCL's own K-4PCS unit test: keypoints only, delta 0.1 m, overlap 0.9, 100 iterations, <= 10 deg and 1 m.
  all.push_back({.name = "eth-office",
                 .data = "ETH office TLS keypoints (PCL's KFPCS test data)",
                 .pairs = "office1 → office2",
                 .sigmas_m = {0.1},
                 .overlap = 0.9,
                 .max_rotation_deg = 10.0,
                 .max_translation_m = 1.0,
                 .trials = trials,
                 .pcl_iterations = 100,
                 .cap_s = q ? 120 : cap_s,  // PCL needs ~50 s for its 100 iterations here
                 .max_bases = 100,
                 .keypoints_given = true,
                 .baseline = false});

  std::vector<Suite> chosen;
  for (Suite& suite : all) {
    const bool simulated = !suite.sizes.empty();
    const bool wanted = o.suites.find(suite.name) != std::string::npos ||
                        (!simulated && o.suites.find("real") != std::string::npos);
    if (wanted) chosen.push_back(std::move(suite));
  }
  return chosen;
}

// Every method a run can have, in the order they take turns within a trial.
const std::vector<std::string>& all_methods() {
  static const std::vector<std::string> methods = {kOursK4pcs, kPclK4pcs, kPclSacIa,  kOpen3dRansac, kOpen3dFgr,
                                                   kOursPlain, kPclPlain, kOursMatch, kPclMatch};
  return methods;
}

std::string method_names() {
  std::string names;
  for (const std::string& m : all_methods()) names += (names.empty() ? "" : ", ") + m;
  return names;
}

bool listed(const std::string& list, const std::string& name) {
  return ("," + list + ",").find("," + name + ",") != std::string::npos;
}

// The methods --methods asks for (all by default), less those whose library is missing: their names and
// why go to `skipped`, for the report.
std::vector<std::string> selected_methods(const std::string& list, std::map<std::string, std::string>& skipped) {
  std::istringstream names(list);
  for (std::string name; std::getline(names, name, ',');)
    if (std::find(all_methods().begin(), all_methods().end(), name) == all_methods().end())
      throw std::runtime_error("--methods: unknown method \"" + name + "\" (known: " + method_names() + ")");
  std::vector<std::string> chosen;
  for (const std::string& m : all_methods())
    if (list.empty() || listed(list, m)) chosen.push_back(m);
  if (std::find(chosen.begin(), chosen.end(), kOpen3dRansac) != chosen.end() ||
      std::find(chosen.begin(), chosen.end(), kOpen3dFgr) != chosen.end()) {
    if (const std::string reason = open3d_unavailable_reason(); !reason.empty())
      for (const char* m : {kOpen3dRansac, kOpen3dFgr})
        if (std::erase(chosen, m)) skipped[m] = reason;
  }
  return chosen;
}

// The methods of one case, in the order they take turns within a trial, among the selected ones.
std::vector<std::string> methods_for(const Suite& suite, const Case& c, int trial,
                                     const std::vector<std::string>& selected) {
  const auto chosen = [&](std::vector<std::string> methods) {
    std::erase_if(methods, [&](const std::string& m) {
      return std::find(selected.begin(), selected.end(), m) == selected.end();
    });
    return methods;
  };
  if (suite.keypoints_given) return chosen({kOursMatch, kPclMatch});  // FPFH needs surfaces, not keypoints
  std::vector<std::string> methods = {kOursK4pcs, kPclK4pcs, kPclSacIa, kOpen3dRansac, kOpen3dFgr};
  const auto& pairs = suite.baseline_pairs;
  const bool baseline = suite.baseline && (suite.baseline_size == 0 || suite.baseline_size == c.points) &&
                        (suite.baseline_sigma_m == 0 || suite.baseline_sigma_m == c.job.sigma_m) &&
                        (pairs.empty() || std::find(pairs.begin(), pairs.end(), c.pair) != pairs.end()) &&
                        trial <= (suite.baseline_trials > 0 ? suite.baseline_trials : suite.trials);
  if (baseline) methods.insert(methods.end(), {kOursPlain, kPclPlain});
  return chosen(methods);
}

std::vector<std::pair<int, int>> station_pairs(const Suite& suite, bool quick) {
  if (suite.name == "lab") {
    if (quick) return {{0, 1}, {0, 2}, {2, 3}};
    std::vector<std::pair<int, int>> all;
    for (int a = 0; a < 6; ++a)
      for (int b = a + 1; b < 6; ++b) all.push_back({a, b});
    return all;
  }
  if (quick) return {{0, 1}};
  return {{0, 1}, {1, 2}, {2, 3}, {3, 0}};
}

Job base_job(const Suite& suite, double sigma_m, const Options& o) {
  Job job;
  job.memory_cap_mb = o.memory_cap_mb;
  job.sigma_m = sigma_m;
  job.overlap = suite.overlap;
  job.pcl_iterations = suite.pcl_iterations;
  job.cap_s = suite.cap_s;
  job.max_bases = suite.max_bases;
  return job;
}

std::string case_label(const Report& report, const Case& c) {
  const Suite& s = report.suites[c.suite];
  char size[32] = "";
  if (c.points) std::snprintf(size, sizeof size, " %.1fM", c.points / 1e6);
  char buffer[200];
  std::snprintf(buffer, sizeof buffer, "%s%s σ=%gmm %s", s.name.c_str(), size, c.job.sigma_m * 1000, c.pair.c_str());
  return buffer;
}

using CaseFilter = std::function<bool(const Case&)>;

void add_simulated_cases(std::size_t index, const Suite& suite, const Options& o, const CaseFilter& keep,
                         std::vector<Case>& cases) {
  for (std::size_t points : suite.sizes)
    for (double sigma : suite.sigmas_m)
      for (const auto& [a, b] : station_pairs(suite, o.quick)) {
        Case c{index, std::to_string(a) + "-" + std::to_string(b), points, base_job(suite, sigma, o)};
        if (!keep(c)) continue;
        const CachedScan source = cached_simulated_scan(o.cache_dir, suite.name, a, points);
        const CachedScan target = cached_simulated_scan(o.cache_dir, suite.name, b, points);
        c.job.source = source.path;
        c.job.target = target.path;
        c.job.truth = source_to_target_truth(source, target);
        cases.push_back(c);
      }
}

// The file a ground-truth entry names: our binary PLY copy in derived/ when there is one.
std::string data_file(const fs::path& folder, const std::string& name) {
  const fs::path derived = folder / "derived" / (fs::path(name).stem().string() + ".ply");
  return fs::exists(derived) ? derived.string() : (folder / name).string();
}

void add_real_cases(std::size_t index, const Suite& suite, const Options& o, const CaseFilter& keep,
                    std::vector<Case>& cases) {
  static const std::map<std::string, std::string> folders = {
      {"bunny", "stanford-bunny-scans"},       {"kurt3d", "3dtk-kurt3d-scans"},
      {"velodyne", "velodyne-pair-fastgicp"},  {"3dmatch", "3dmatch-pair-geotransformer"},
      {"eth-office", "eth-office-tls-keypoints"}};
  const fs::path folder = fs::path(o.data_dir) / folders.at(suite.name);
  std::vector<GtPair> pairs = read_gt_pairs((folder / "gt_pairs.log").string());
  if (suite.name == "bunny") {
    std::stable_sort(pairs.begin(), pairs.end(), [](const GtPair& a, const GtPair& b) { return a.overlap > b.overlap; });
    pairs.resize(std::min<std::size_t>(pairs.size(), 10));
  }
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    Case c{index, fs::path(pairs[i].source).stem().string() + "->" + fs::path(pairs[i].target).stem().string(), 0,
           base_job(suite, suite.sigmas_m.front(), o)};
    c.job.source = data_file(folder, pairs[i].source);
    c.job.target = data_file(folder, pairs[i].target);
    c.job.truth = pairs[i].T_target_source;
    c.job.pose_seed = 1000 * (index + 1) + i;
    if (suite.name == "kurt3d") c.job.unit_scale = 0.01, c.job.max_range_m = 32.0;  // cm; 3277 cm = no return
    if (keep(c)) cases.push_back(c);
  }
}

// ---- running workers ----

ChildOutcome run_worker(const Job& job) {
  const std::string self = fs::read_symlink("/proc/self/exe").string();
  return run_child({self, "worker", "--job", json(job).dump()}, job.cap_s + kHardLimitSlack_s);
}

// A run during which other processes used more than this many cores on average (and 0.2 CPU seconds in
// all, above the noise of the clock ticks) is repeated once the machine is quiet again.
constexpr double kMaxForeignCores = 0.25, kMinForeignCpu_s = 0.2;
constexpr int kMaxAttempts = 3;             // the last attempt stands (and says how busy the machine was)
constexpr double kMaxQuietWait_s = 3600.0;  // then the run goes ahead regardless

struct MeasuredOutcome {
  ChildOutcome child;
  int attempts = 0;
  double foreign_cores = 0;
};

// A worker stopped from outside (the session ends, someone presses Ctrl-C): the comparison stops too,
// without journaling that run as a failure, and --resume continues it.
struct Interrupted : std::runtime_error {
  using std::runtime_error::runtime_error;
};

MeasuredOutcome run_measured(const Job& job) {
  MeasuredOutcome m;
  for (;;) {
    const double busy = machine_busy_cpu_s();
    m.child = run_worker(job);
    ++m.attempts;
    const int signal = m.child.signal;
    if (!m.child.timed_out && (signal == SIGTERM || signal == SIGINT || signal == SIGHUP || signal == SIGKILL))
      throw Interrupted("a worker was stopped from outside (signal " + std::to_string(signal) +
                        "); the journal has every finished run: continue with --resume");
    const double foreign_s = machine_busy_cpu_s() - busy - m.child.cpu_s;
    m.foreign_cores = std::max(0.0, foreign_s / std::max(m.child.wall_s, 1e-3));
    if (m.foreign_cores <= kMaxForeignCores || foreign_s < kMinForeignCpu_s || m.attempts == kMaxAttempts) return m;
    std::printf("  (other processes used %.2f cores during that run: waiting for a quiet machine to repeat it)\n",
                m.foreign_cores);
    std::fflush(stdout);
    wait_until_quiet(kMaxForeignCores, kMaxQuietWait_s);
  }
}

// The worker's RESULT line; for a run that died, the facts of its last PROGRESS line (and an error).
json worker_result(const ChildOutcome& child, int memory_cap_mb, std::string& error) {
  const std::size_t at = child.output.rfind("RESULT ");
  if (at != std::string::npos && !child.timed_out) return json::parse(child.output.substr(at + 7));
  if (child.timed_out)
    error = "killed after the hard time limit";
  else if (child.output.find(std::string("\n") + kOutOfMemoryLine + "\n") != std::string::npos)
    error = "out of memory (over the " + std::to_string(memory_cap_mb) + " MB cap)";
  else
    error = "worker crashed (exit " + std::to_string(child.exit_code) + ")";
  const std::size_t progress = child.output.rfind("PROGRESS ");
  if (progress == std::string::npos) return json::object();
  const std::size_t end = child.output.find('\n', progress);
  return json::parse(child.output.substr(progress + 9, end - progress - 9));
}

Errors errors_from(const json& j) {
  if (!j.is_object()) return {};
  return {j.value("mae_deg", 0.0), j.value("mte_m", 0.0), j.value("rotation_deg", 0.0), j.value("translation_m", 0.0),
          j.value("rmse_m", 0.0)};
}

bool succeeded(const Suite& suite, const Errors& e) {
  if (suite.max_rotation_deg > 0) return e.rotation_deg <= suite.max_rotation_deg && e.translation_m <= suite.max_translation_m;
  return e.rmse_m < suite.success_rmse_m;
}

Run make_run(const Report& report, std::size_t case_index, const std::string& method, int trial,
             const MeasuredOutcome& measured) {
  const ChildOutcome& child = measured.child;
  Run run;
  run.case_index = case_index;
  run.method = method;
  run.trial = trial;
  run.attempts = measured.attempts;
  run.foreign_cores = measured.foreign_cores;
  const json r = worker_result(child, report.cases[case_index].job.memory_cap_mb, run.error);
  // PCL's K-4PCS starts from SIFT keypoints computed once per scan: their process's memory counts too.
  run.peak_rss_mb = std::max(child.peak_rss_mb, r.value("sift_peak_rss_mb", 0.0));
  run.capped = child.timed_out || r.value("capped", false);
  run.ok = r.value("ok", false);
  if (run.error.empty()) run.error = r.value("error", "");
  run.read_s = r.value("read_s", 0.0);
  run.convert_s = r.value("convert_s", 0.0);
  run.total_s = r.value("total_s", 0.0);
  run.source_keypoints = r.value("source_keypoints", std::size_t{0});
  run.target_keypoints = r.value("target_keypoints", std::size_t{0});
  run.sift_overflow_octaves = r.value("sift_overflow_octaves", 0);
  if (r.contains("stages"))
    for (const auto& [stage, s] : r["stages"].items()) run.stages[stage] = s.get<double>();
  run.coarse = errors_from(r.value("coarse", json()));
  run.final = errors_from(r.value("final", json()));
  const Suite& suite = report.suites[report.cases[case_index].suite];
  run.success_coarse = run.ok && !run.capped && succeeded(suite, run.coarse);
  run.success_final = run.ok && !run.capped && succeeded(suite, run.final);
  return run;
}

// Runs one detector job; ours also fills the grid spacing and truth check of `k`.
DetectorStats run_detector_job(const Case& c, const char* method, KeypointStats& k) {
  Job job = c.job;
  job.method = method;
  const MeasuredOutcome measured = run_measured(job);
  const ChildOutcome& child = measured.child;
  // SIFT is deterministic: the scan it was computing when killed is not tried again (sift_cache.h).
  if (child.timed_out) SiftCache(job.sift_cache_dir).mark_running_as_timed_out(job.cap_s);
  DetectorStats d;
  d.attempts = measured.attempts;
  d.foreign_cores = measured.foreign_cores;
  const json r = worker_result(child, job.memory_cap_mb, d.error);
  d.peak_rss_mb = std::max(child.peak_rss_mb, r.value("sift_peak_rss_mb", 0.0));
  d.timed_out = child.timed_out || r.value("sift_timed_out", false);
  d.ok = r.value("ok", false);
  if (d.error.empty()) d.error = r.value("error", "");
  d.source = r.value("source_keypoints", std::size_t{0});
  d.target = r.value("target_keypoints", std::size_t{0});
  d.repeatability = r.value("repeatability", 0.0);
  d.seconds = r.value("seconds", child.wall_s);
  d.sift_overflow_octaves = r.value("sift_overflow_octaves", 0);
  if (d.ok && r.contains("plain_voxel_m")) {
    k.plain_voxel_m = r["plain_voxel_m"];
    k.truth_overlap = r["truth_overlap"];
  }
  return d;
}

// Why a run is not worth starting (recorded as a failed run), or "" to run it.
std::string skip_reason(const std::string& method, const KeypointStats& k) {
  if (method == kPclK4pcs && k.pcl.timed_out)
    return "not run: PCL's SIFTKeypoint alone (deterministic) passed the hard limit in the keypoint job";
  if ((method == kOursPlain || method == kPclPlain) && k.plain_voxel_m <= 0)
    return "not run: no plain-4PCS grid (our keypoint job failed)";
  return "";
}

void print_detector(const char* name, const DetectorStats& d) {
  if (d.ok)
    std::printf(" %s %zu/%zu (repeatability %.0f %%, %.1f s)", name, d.source, d.target, 100 * d.repeatability, d.seconds);
  else if (d.error.starts_with("not run"))
    std::printf(" %s %s", name, d.error.c_str());
  else
    std::printf(" %s ERROR %s", name, d.error.c_str());
}

std::string now_text(bool with_seconds = false) {
  const std::time_t t = std::time(nullptr);
  char buffer[64];
  std::strftime(buffer, sizeof buffer, with_seconds ? "%Y-%m-%d %H:%M:%S %Z" : "%Y-%m-%d %H:%M %Z", std::localtime(&t));
  return buffer;
}

void print_run(const Report& report, const Run& run, std::size_t done, std::size_t total, double elapsed_s) {
  const Case& c = report.cases[run.case_index];
  std::printf("[%zu/%zu %s] %s trial %d %-10s ", done, total, clock_text(elapsed_s).c_str(),
              case_label(report, c).c_str(), run.trial, run.method.c_str());
  if (run.ok)
    std::printf("%s RMSE coarse %.4g final %.4g, rot %.1f deg, %.2f s, %zu/%zu kp, %.0f MB%s\n",
                run.success_coarse ? "OK  " : "FAIL", run.coarse.rmse_m, run.final.rmse_m, run.coarse.rotation_deg,
                run.total_s, run.source_keypoints, run.target_keypoints, run.peak_rss_mb, run.capped ? " (capped)" : "");
  else
    std::printf("ERROR %s\n", run.error.c_str());
  std::fflush(stdout);
}

int run_comparison(const Options& o, const std::string& command) {
  const auto start = std::chrono::steady_clock::now();
  const auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  Report report;
  report.mode = o.quick ? "quick" : "full";
  report.started = now_text();
  report.command = command;
  report.suites = make_suites(o);
  const std::vector<std::string> selected = selected_methods(o.methods, report.skipped_methods);
  for (const auto& [method, reason] : report.skipped_methods)
    std::printf("skipping %s: %s\n", method.c_str(), reason.c_str());
  // PCL's SIFT serves only its K-4PCS: without it, the keypoint job runs our detector alone.
  const bool pcl_sift = std::find(selected.begin(), selected.end(), kPclK4pcs) != selected.end();
  const CaseFilter keep = [&](const Case& c) { return case_label(report, c).find(o.only) != std::string::npos; };
  for (std::size_t i = 0; i < report.suites.size(); ++i) {
    if (report.suites[i].sizes.empty()) add_real_cases(i, report.suites[i], o, keep, report.cases);
    else add_simulated_cases(i, report.suites[i], o, keep, report.cases);
  }
  report.keypoints.resize(report.cases.size());
  const std::string sift_cache_dir = (fs::path(o.cache_dir) / "sift").string();
  SiftCache(sift_cache_dir).forget_running();  // no worker runs now
  for (Case& c : report.cases) c.job.sift_cache_dir = sift_cache_dir;

  fs::create_directories(o.results_dir);
  Journal journal(o.results_dir + "/compare-" + report.mode + "-journal.jsonl", o.resume, now_text(true));
  const JournalReplay& replay = journal.replay();
  if (o.report_only && replay.sessions == 0)
    throw std::runtime_error("--report-only: nothing journaled yet in " + o.results_dir + " (" + report.mode + " mode)");
  if (!replay.first_started.empty()) report.started = replay.first_started.substr(0, 16) + " UTC";
  bool ran_any = false;  // a resume with nothing left to run only rewrites the outputs
  if (!o.report_only && wait_until_quiet(kMaxForeignCores, kMaxQuietWait_s).waited_s > 10.0)
    std::printf("waited for a quiet machine\n");

  std::size_t total = 0, done = 0;
  for (const Case& c : report.cases)
    for (int trial = 1; trial <= report.suites[c.suite].trials; ++trial)
      for (const std::string& method : methods_for(report.suites[c.suite], c, trial, selected)) {
        ++total;
        ++report.planned[{c.suite, c.points, c.job.sigma_m, method}];
      }
  for (std::size_t ci = 0; ci < report.cases.size(); ++ci) {
    Case& c = report.cases[ci];
    const std::string label = case_label(report, c);
    const Suite& suite = report.suites[c.suite];
    KeypointStats& k = report.keypoints[ci];
    const auto redone = [&](const std::string& method) { return listed(o.redo, method); };
    if (const auto it = replay.keypoints.find(label); it != replay.keypoints.end() && !redone("keypoints")) {
      k = it->second;
    } else if (o.report_only && !suite.keypoints_given) {
      continue;  // not reached yet
    } else if (!suite.keypoints_given) {
      k.ran = true;
      k.ours = run_detector_job(c, kKeypointsOurs, k);
      if (pcl_sift)
        k.pcl = run_detector_job(c, kKeypointsPcl, k);
      else
        k.pcl.error = std::string("not run: ") + kPclK4pcs + " is not among --methods";
      journal.add(label, k, elapsed());
      ran_any = true;
      std::printf("[%s] %s keypoints:", clock_text(elapsed()).c_str(), label.c_str());
      print_detector("k4reg", k.ours);
      print_detector("PCL SIFT", k.pcl);
      std::printf(", voxel overlap under the truth %.0f %%, 4PCS grid %.3f m\n", 100 * k.truth_overlap, k.plain_voxel_m);
    }
    c.job.plain_voxel_m = k.plain_voxel_m;
    for (int trial = 1; trial <= suite.trials; ++trial)
      for (const std::string& method : methods_for(suite, c, trial, selected)) {
        ++done;
        if (const auto it = replay.runs.find({label, method, trial}); it != replay.runs.end() && !redone(method)) {
          report.runs.push_back(it->second);
          report.runs.back().case_index = ci;
          continue;
        }
        if (o.report_only) continue;
        Job job = c.job;
        job.method = method;
        job.seed = static_cast<std::uint64_t>(trial);
        const std::string skip = skip_reason(method, k);
        if (skip.empty()) {
          report.runs.push_back(make_run(report, ci, method, trial, run_measured(job)));
        } else {
          Run run;
          run.case_index = ci, run.method = method, run.trial = trial, run.capped = true, run.error = skip;
          report.runs.push_back(run);
        }
        journal.add(label, report.runs.back(), elapsed());
        ran_any = true;
        print_run(report, report.runs.back(), done, total, elapsed());
      }
  }
  report.sessions = replay.sessions + (ran_any ? 1 : 0);
  report.duration_s = replay.earlier_sessions_s + (ran_any ? elapsed() : 0.0);
  write_outputs(report, o.results_dir);
  replace_block(o.markdown, "compare-" + report.mode, markdown(report, path_from_markdown(o.markdown, o.results_dir)));
  std::printf("%s: %s of machine time in %d session(s) (%s mode, %zu of %zu runs); results in %s and %s\n",
              report.runs.size() < total ? "progress report" : "comparison finished",
              clock_text(report.duration_s).c_str(), report.sessions, report.mode.c_str(), report.runs.size(), total,
              o.results_dir.c_str(), o.markdown.c_str());
  return 0;
}

// ---- Google Benchmark JSON -> the voxel grid table ----

int voxel_report(const std::string& json_path, const std::string& markdown_path) {
  std::ifstream in(json_path);
  const json j = json::parse(in);
  struct Cell {
    double ours_ms = 0, ours_one_ms = 0, pcl_ms = 0, ours_out = 0, pcl_out = 0, points_in = 0, pcl_cells = 0;
  };
  std::map<int, Cell> by_leaf;
  double convert_ms = 0;
  for (const json& b : j.at("benchmarks")) {
    if (b.value("aggregate_name", "") != "median") continue;
    const std::string name = b.at("run_name");
    const double ms = b.at("real_time");
    if (name.starts_with("BM_ConvertToPcl")) {
      convert_ms = ms;
      continue;
    }
    Cell& cell = by_leaf[std::stoi(name.substr(name.find("leaf_mm:") + 8))];
    cell.points_in = b.value("points_in", 0.0);
    if (name.starts_with("BM_OursVoxelGridOneThread")) cell.ours_one_ms = ms;
    else if (name.starts_with("BM_OursVoxelGrid")) cell.ours_ms = ms, cell.ours_out = b.value("points_out", 0.0);
    else cell.pcl_ms = ms, cell.pcl_out = b.value("points_out", 0.0), cell.pcl_cells = b.value("pcl_grid_cells", 0.0);
  }
  const auto ratio = [](double a, double b) { return b > 0 ? a / b : 0.0; };
  std::ostringstream md;
  md << std::fixed << "### Voxel grid: k4reg::voxel_grid vs pcl::VoxelGrid<PointXYZI>\n\n"
     << "One simulated 10 M-point lab scan (station 0), centroid voxel grid, medians of 5 repetitions (Google "
        "Benchmark, wall time). k4reg runs on both cores (TBB default) and, for a per-core comparison, in a "
        "one-thread arena; PCL's VoxelGrid is single-threaded and is timed on a PCL cloud built beforehand "
        "(building it, not included, takes "
     << std::setprecision(0) << convert_ms << " ms).\n\n"
     << "| leaf | input points | k4reg ms (2 threads) | k4reg ms (1 thread) | k4reg voxels | PCL ms | PCL output points "
        "| PCL refused the grid (> 2^31 cells)? | PCL / k4reg (2 threads) | PCL / k4reg (1 thread) |\n"
     << "|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& [leaf, c] : by_leaf)
    md << "| " << leaf << " mm | " << std::setprecision(0) << c.points_in << " | " << c.ours_ms << " | " << c.ours_one_ms
       << " | " << c.ours_out << " | " << c.pcl_ms << " | " << c.pcl_out << " | "
       << (c.pcl_cells > std::numeric_limits<std::int32_t>::max() ? "yes" : "no") << " (" << std::setprecision(2)
       << c.pcl_cells / 1e6 << " M cells) | " << std::setprecision(1) << ratio(c.pcl_ms, c.ours_ms)
       << "× | " << ratio(c.pcl_ms, c.ours_one_ms) << "× |\n";
  md << "\nRaw data: `results/voxel_grid_bench.json`. (Google Benchmark warns that Debian's libbenchmark "
        "itself was built in debug mode; that affects its bookkeeping, not the code under test, which is "
        "built Release.)\n";
  replace_block(markdown_path, "voxel", md.str());
  std::printf("%s", md.str().c_str());
  return 0;
}

}  // namespace
}  // namespace k4reg::bench

int main(int argc, char** argv) {
  using namespace k4reg::bench;
  CLI::App app{"K-4PCS / 4PCS benchmark: k4reg vs PCL 1.13 on simulated and real scan pairs"};
  Options o;
  app.add_flag("--quick", o.quick, "representative subset (about 20 min on 2 cores)");
  app.add_flag("--resume", o.resume,
               "continue an interrupted comparison from its journal (same build and options): only missing runs run");
  app.add_option("--redo", o.redo,
                 "with --resume: measure these methods again, e.g. k4pcs-ours,keypoints after a change to the core "
                 "(PCL's runs do not depend on it)")
      ->needs("--resume");
  app.add_flag("--report-only", o.report_only,
               "with --resume: write the CSVs, plots and markdown from the journal so far and run nothing (a "
               "progress report; rows still missing runs are marked partial)")
      ->needs("--resume");
  app.add_option("--trials", o.trials, "trials per pair and method (default: 3 quick, 10 full; 0: keypoint jobs only)");
  app.add_option("--methods", o.methods,
                 "comma-separated methods to run (default: all whose library is installed): " + method_names());
  app.add_option("--suites", o.suites, "comma-separated: lab, arch, real (all real data) or a real set's name")
      ->capture_default_str();
  app.add_option("--only", o.only, "run only the pairs whose label contains this text (e.g. \"lab 0.7M\")");
  app.add_option("--cache-dir", o.cache_dir, "simulated scans are cached here")->capture_default_str();
  app.add_option("--results-dir", o.results_dir, "CSV files and plot scripts go here")->capture_default_str();
  app.add_option("--markdown", o.markdown, "file whose compare-<mode> block is replaced")->capture_default_str();
  app.add_option("--data-dir", o.data_dir, "the real data sets")->capture_default_str();
  app.add_option("--memory-cap-mb", o.memory_cap_mb, "address-space limit per run (the machine may be shared)")
      ->capture_default_str();

  CLI::App* worker = app.add_subcommand("worker", "run one job (JSON) and print its result (internal)");
  std::string job_text;
  worker->add_option("--job", job_text, "the job as JSON")->required();
  CLI::App* voxel = app.add_subcommand("voxel-report", "turn voxel_grid_bench's JSON into the voxel block");
  std::string voxel_json, voxel_markdown = "bench/RESULTS.md";
  voxel->add_option("--json", voxel_json, "Google Benchmark JSON output")->required();
  voxel->add_option("--markdown", voxel_markdown, "file whose voxel block is replaced")->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  try {
    if (worker->parsed()) {
      const Job job = json::parse(job_text).get<Job>();
      limit_memory(job);
      const json result = run_job(job);
      std::printf("RESULT %s\n", result.dump().c_str());
      return 0;
    }
    if (voxel->parsed()) return voxel_report(voxel_json, voxel_markdown);
    std::string command = "k4reg-bench-compare";
    // A progress report names the command that makes (and continues) the runs it reports.
    for (int i = 1; i < argc; ++i)
      if (std::string(argv[i]) != "--report-only") command += std::string(" ") + argv[i];
    return run_comparison(o, command);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "k4reg-bench-compare: %s\n", e.what());
    return 1;
  }
}
