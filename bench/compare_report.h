// The comparison's data model (suites, cases, runs) and its outputs: per-run and per-row CSV files,
// the markdown block of bench/results/comparison-with-pcl.md (a summary of every system per suite, the paper's
// Tables 2-4 with PCL beside us, plus every row in detail) and gnuplot scripts for the plots.
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "compare_job.h"

namespace k4reg::bench {

// One configuration per suite; every pair of the suite runs with it (no per-pair tuning).
struct Suite {
  std::string name;                 // "lab", "arch", "bunny", "kurt3d", "velodyne", "3dmatch", "eth-office"
  std::string data;                 // what the scans are, for RESULTS.md
  std::string pairs;                // which pairs, for RESULTS.md
  std::vector<std::size_t> sizes{};  // simulated scan sizes (points); empty for real data
  std::vector<double> sigmas_m{};
  double overlap = 0.8;
  double success_rmse_m = 0.5;      // success: true-correspondence RMSE below this...
  double max_rotation_deg = 0.0;    // ...or, when these are set, rotation and translation errors within them
  double max_translation_m = 0.0;
  int trials = 10;
  int pcl_iterations = 100;
  int cap_s = 600;
  int max_bases = 0;                // ours (0 = from the overlap, like PCL's automatic count)
  bool keypoints_given = false;     // the clouds are keypoints (ETH office): only the 4PCS stage runs
  bool baseline = true;             // also run plain 4PCS (ours and PCL) ...
  std::size_t baseline_size = 0;    // ... at this scan size only (0 = every size) ...
  int baseline_trials = 0;          // ... with this many trials (0 = trials) ...
  double baseline_sigma_m = 0;      // ... at this sigma only (0 = every sigma) ...
  std::vector<std::string> baseline_pairs{};  // ... on these pairs only (empty = every pair)
};

struct Case {
  std::size_t suite = 0;            // index into the suite list
  std::string pair;                 // "0-1", "bun045->bun000"
  std::size_t points = 0;           // requested simulated scan size; 0 for real data
  Job job;                          // files, truth, sigma, overlap, caps; method and seed set per run
};

struct Errors {
  double mae_deg = 0, mte_m = 0, rotation_deg = 0, translation_m = 0, rmse_m = 0;
};

struct Run {
  std::size_t case_index = 0;
  std::string method;
  int trial = 0;
  bool ok = false;        // the method returned a transform
  bool capped = false;    // over the wall-time cap (or killed): a failure
  bool success_coarse = false, success_final = false;
  std::string error;
  Errors coarse, final;
  std::map<std::string, double> stages;
  double total_s = 0, read_s = 0, convert_s = 0, peak_rss_mb = 0;
  std::size_t source_keypoints = 0, target_keypoints = 0;
  int sift_overflow_octaves = 0;
  int attempts = 1;          // > 1: repeated because other processes used the CPU (see machine_load.h)
  double foreign_cores = 0;  // cores other processes used on average during the attempt that stands
};

// A detector run once per case (detectors are deterministic): counts, repeatability, time.
struct DetectorStats {
  bool ok = false;
  bool timed_out = false;           // killed at the hard limit
  std::string error;
  std::size_t source = 0, target = 0;
  double repeatability = 0, seconds = 0, peak_rss_mb = 0;
  int sift_overflow_octaves = 0;    // PCL only
  int attempts = 1;
  double foreign_cores = 0;
};

struct KeypointStats {
  bool ran = false;                 // false for keypoint-only data (ETH office)
  DetectorStats ours, pcl;
  double truth_overlap = 0;         // share of source voxels within 2 sigma of a target voxel under the truth
  double plain_voxel_m = 0;         // the plain-4PCS grid (from our keypoint count); 0 = unknown
};

struct Report {
  std::string mode;                 // "quick" or "full"
  std::string started, command;
  double duration_s = 0;            // machine time, summed over the sessions of a resumed comparison
  int sessions = 1;
  std::vector<Suite> suites;
  std::vector<Case> cases;
  std::vector<KeypointStats> keypoints;  // parallel to cases
  std::vector<Run> runs;
  // Runs the configuration asks for, per table row (suite, points, sigma_m, method): a report made before
  // the comparison finished (--report-only) marks its rows partial.
  std::map<std::tuple<std::size_t, std::size_t, double, std::string>, std::size_t> planned;
  std::map<std::string, std::string> skipped_methods;  // asked for (or by default) but not runnable here: why
};

// Writes <dir>/compare-<mode>-runs.csv, -rows.csv and the gnuplot scripts -sr-vs-sigma.gp and
// -time-vs-size.gp (inline data; run by bench/run.sh to make the PNGs next to them).
void write_outputs(const Report& report, const std::string& dir);

// The markdown block for bench/results/comparison-with-pcl.md.
std::string markdown(const Report& report, const std::string& results_dir_in_repo);

}  // namespace k4reg::bench
