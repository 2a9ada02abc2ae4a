// k4reg-bench-table2: the paper's Table 2 (Theiler et al. 2014) for our K-4PCS on the simulated indoor lab.
// For every scan size and minimum scale σ, every chosen station pair is registered with every seed, in this
// process, with one configuration for all: mean keypoints, success rate, RMSE against the ground truth,
// median time per stage, end-to-end median and p90, peak RSS.
//
//   k4reg-bench-table2 [--quick] [--sizes 700000,2500000,10000000] [--sigmas 0.025,0.05,0.1] [--pairs 0-1,2-3]
//                      [--seeds 10] [--threads N] [--cache-dir DIR] [--results-dir DIR] [--markdown FILE]
//
// Each finished row is merged at once into <results-dir>/table2-rows.csv and table2-runs.csv (it replaces an
// earlier row with the same size, σ, pairs and seeds; other rows stay) and the "table2" block of the markdown
// file is rebuilt from all rows: the full grid (hours) can be measured in pieces, and an interrupted run keeps
// the rows it finished.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "k4reg/io/cloud_io.h"
#include "k4reg/util/error.h"
#include "k4reg/registration/metrics.h"
#include "k4reg/registration/registration.h"
#include "markdown_block.h"
#include "paper_tables.h"
#include "sim/scene.h"
#include "simulated_scan_cache.h"
#include "statistics.h"
#include "table_format.h"
#include "truth_error.h"

namespace fs = std::filesystem;

namespace k4reg::bench {
namespace {

using Clock = std::chrono::steady_clock;

constexpr const char* kScene = "lab";
constexpr double kOverlap = 0.8;  // the paper's setting for the indoor suite
// The design of the paper's Table 2: every size and σ, all station pairs, 10 seeds.
constexpr std::array<std::size_t, 3> kFullSizes = {700000, 2500000, 10000000};
constexpr std::array<double, 3> kFullSigmas_m = {0.025, 0.05, 0.1};
constexpr int kFullSeeds = 10;
// register_clouds' stages, in pipeline order (core/src/registration/registration.cpp).
constexpr std::array<const char*, 6> kStages = {"voxel_grid", "keypoints", "matching",
                                                "icp_setup",  "symmetry_guard", "icp"};

struct Options {
  bool quick = false;
  std::vector<std::size_t> sizes{kFullSizes.begin(), kFullSizes.end()};
  std::vector<double> sigmas_m{kFullSigmas_m.begin(), kFullSigmas_m.end()};
  std::string pairs;  // "" = all station pairs
  int seeds = kFullSeeds;
  int threads = 0;    // 0 = all cores
  std::string cache_dir = "build-bench/bench-cache";
  std::string results_dir = "bench/results";
  std::string markdown = "bench/RESULTS.md";
};

struct StationPair {
  int source = 0, target = 0;
};

// The one configuration of every run: RegistrationParams' defaults (the paper's Tab. 1) but for σ, the
// overlap, the seed and the thread count.
RegistrationParams table2_params(double sigma_m, std::uint64_t seed, int threads) {
  RegistrationParams params;
  params.min_scale_m = sigma_m;
  params.overlap = kOverlap;
  params.seed = seed;
  params.threads = threads;
  return params;
}

// ---- station pairs ----

std::vector<StationPair> all_pairs(int stations) {
  std::vector<StationPair> pairs;
  for (int a = 0; a < stations; ++a)
    for (int b = a + 1; b < stations; ++b) pairs.push_back({a, b});
  return pairs;
}

int parse_station(std::string_view text, int stations, const std::string& item) {
  int station = -1;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), station);
  if (error != std::errc() || end != text.data() + text.size() || station < 0 || station >= stations)
    throw std::runtime_error("--pairs: \"" + item + "\" is not SOURCE-TARGET with stations 0 to " +
                             std::to_string(stations - 1));
  return station;
}

// "0-1,2-3" -> {{0, 1}, {2, 3}}; "" -> all pairs.
std::vector<StationPair> parse_pairs(const std::string& text, int stations) {
  if (text.empty()) return all_pairs(stations);
  std::vector<StationPair> pairs;
  std::stringstream list(text);
  for (std::string item; std::getline(list, item, ',');) {
    const std::size_t dash = item.find('-');
    if (dash == std::string::npos) throw std::runtime_error("--pairs: \"" + item + "\" is not SOURCE-TARGET");
    const StationPair pair{parse_station(std::string_view(item).substr(0, dash), stations, item),
                           parse_station(std::string_view(item).substr(dash + 1), stations, item)};
    if (pair.source == pair.target) throw std::runtime_error("--pairs: \"" + item + "\" pairs a station with itself");
    pairs.push_back(pair);
  }
  if (pairs.empty()) throw std::runtime_error("--pairs: no pair given");
  return pairs;
}

// The pairs as stored in the CSV key (no commas): "all" or "0-1 2-3".
std::string pairs_key(const std::vector<StationPair>& pairs, int stations) {
  const auto all = all_pairs(stations);
  const auto same = [](const StationPair& a, const StationPair& b) { return a.source == b.source && a.target == b.target; };
  if (pairs.size() == all.size() && std::equal(pairs.begin(), pairs.end(), all.begin(), same)) return "all";
  std::string key;
  for (const StationPair& p : pairs) key += (key.empty() ? "" : " ") + std::to_string(p.source) + "-" + std::to_string(p.target);
  return key;
}

// ---- one registration ----

struct Run {
  StationPair pair;
  int seed = 0;
  bool ok = false;     // register_clouds returned a transform
  std::string error;   // its typed error otherwise
  std::size_t source_keypoints = 0, target_keypoints = 0;
  TransformError coarse, final;  // coarse = the best hypothesis after the symmetry guard (before the final ICP)
  bool success_coarse = false, success_final = false;
  std::array<double, kStages.size()> stage_s{};
  double total_s = 0;  // register_clouds' wall time (also for a run that ends in an error)
};

Run register_pair(const PointCloud& source, const PointCloud& target, const Eigen::Matrix4d& truth,
                  const StationPair& pair, double sigma_m, int seed, int threads) {
  Run run;
  run.pair = pair;
  run.seed = seed;
  run.stage_s.fill(kNan);
  const auto start = Clock::now();
  try {
    const RegistrationResult r = register_clouds(source, target, table2_params(sigma_m, seed, threads));
    run.total_s = std::chrono::duration<double>(Clock::now() - start).count();
    run.ok = true;
    run.source_keypoints = r.source_keypoints;
    run.target_keypoints = r.target_keypoints;
    run.coarse = file_frame_error(source, r.hypotheses.front().transform, truth);
    run.final = file_frame_error(source, r.transform, truth);
    run.success_coarse = registration_succeeded(run.coarse, kIndoorSuccessRmse_m);
    run.success_final = registration_succeeded(run.final, kIndoorSuccessRmse_m);
    for (const StageTiming& t : r.timings)
      for (std::size_t i = 0; i < kStages.size(); ++i)
        if (t.stage == kStages[i]) run.stage_s[i] = t.seconds;
  } catch (const Error& e) {
    run.total_s = std::chrono::duration<double>(Clock::now() - start).count();
    run.error = std::string(to_string(e.code())) + ": " + e.what();
  }
  return run;
}

// ---- peak memory of this process, per row ----

// Resets VmHWM to the current RSS (Linux >= 4.0), so each row reports its own peak.
void reset_peak_rss() {
  std::ofstream clear("/proc/self/clear_refs");
  if (!(clear << "5" << std::flush)) throw std::runtime_error("cannot reset the peak RSS via /proc/self/clear_refs");
}

double peak_rss_mb() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.starts_with("VmHWM:")) return std::stod(line.substr(6)) / 1024.0;
  throw std::runtime_error("no VmHWM in /proc/self/status");
}

// ---- one row of the table ----

struct Row {
  std::size_t points = 0;
  double sigma_m = 0;
  std::string pairs;     // "all" or "0-1 2-3"
  int seeds = 0;
  std::string measured;  // start, UTC
  double pair_count = 0, runs = 0, errors = 0, threads = 0, duration_s = 0;
  double load_average = 0, load_average_end = 0;            // 1-minute load at the row's start and end
  double source_keypoints = 0, target_keypoints = 0;        // means over the runs that returned
  double sr_coarse = 0, sr_final = 0;                        // over all runs
  double rmse_final_median_m = 0;                            // over the runs that succeeded after ICP
  double read_median_s = 0;                                  // reading one pair's files
  double total_median_s = 0, total_p90_s = 0, peak_rss_mb = 0;
  std::array<double, kStages.size()> stage_median_s{};       // over the runs that returned

  bool full_design() const {
    return pairs == "all" && seeds == kFullSeeds &&
           std::find(kFullSizes.begin(), kFullSizes.end(), points) != kFullSizes.end() &&
           std::find(kFullSigmas_m.begin(), kFullSigmas_m.end(), sigma_m) != kFullSigmas_m.end();
  }
};

// The numeric CSV columns after points, sigma_m, pairs, seeds, measured (stage medians follow them).
struct Column {
  const char* name;
  double Row::*field;
};
constexpr Column kColumns[] = {
    {"pair_count", &Row::pair_count},           {"runs", &Row::runs},
    {"errors", &Row::errors},                   {"threads", &Row::threads},
    {"load_average", &Row::load_average},       {"load_average_end", &Row::load_average_end},
    {"duration_s", &Row::duration_s},
    {"source_keypoints_mean", &Row::source_keypoints}, {"target_keypoints_mean", &Row::target_keypoints},
    {"sr_coarse", &Row::sr_coarse},             {"sr_final", &Row::sr_final},
    {"rmse_final_median_m", &Row::rmse_final_median_m}, {"read_median_s", &Row::read_median_s},
    {"total_median_s", &Row::total_median_s},   {"total_p90_s", &Row::total_p90_s},
    {"peak_rss_mb", &Row::peak_rss_mb}};

std::vector<double> collect(const std::vector<Run>& runs, bool (*keep)(const Run&), double (*value)(const Run&)) {
  std::vector<double> v;
  for (const Run& r : runs)
    if (keep(r)) v.push_back(value(r));
  return v;
}

bool returned(const Run& r) { return r.ok; }
bool any_run(const Run&) { return true; }

void summarise(const std::vector<Run>& runs, Row& row) {
  row.runs = runs.size();
  row.errors = std::count_if(runs.begin(), runs.end(), [](const Run& r) { return !r.ok; });
  row.source_keypoints = mean(collect(runs, returned, [](const Run& r) { return double(r.source_keypoints); }));
  row.target_keypoints = mean(collect(runs, returned, [](const Run& r) { return double(r.target_keypoints); }));
  row.sr_coarse = mean(collect(runs, any_run, [](const Run& r) { return double(r.success_coarse); }));
  row.sr_final = mean(collect(runs, any_run, [](const Run& r) { return double(r.success_final); }));
  row.rmse_final_median_m = median(
      collect(runs, [](const Run& r) { return r.success_final; }, [](const Run& r) { return r.final.rmse_m; }));
  const auto total = collect(runs, any_run, [](const Run& r) { return r.total_s; });
  row.total_median_s = median(total);
  row.total_p90_s = percentile(total, 0.9);
  for (std::size_t i = 0; i < kStages.size(); ++i) {
    std::vector<double> v;
    for (const Run& r : runs)
      if (r.ok) v.push_back(r.stage_s[i]);
    row.stage_median_s[i] = median(v);
  }
}

// ---- CSV files, merged row by row ----

std::string csv_number(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream in(line);
  for (std::string field; std::getline(in, field, ',');) fields.push_back(field);
  if (line.ends_with(",")) fields.emplace_back();
  return fields;
}

// The first four fields (points, sigma_m, pairs, seeds) name the row a line belongs to.
std::string row_key(const std::string& line) {
  const auto fields = split_csv(line);
  if (fields.size() < 4) throw std::runtime_error("malformed line: " + line);
  return fields[0] + "," + fields[1] + "," + fields[2] + "," + fields[3];
}

// Rewrites path with its lines of other rows kept and new_lines appended; returns all data lines.
std::vector<std::string> merge_csv(const std::string& path, const std::string& header,
                                   const std::vector<std::string>& new_lines) {
  std::set<std::string> replaced;
  for (const std::string& line : new_lines) replaced.insert(row_key(line));
  std::vector<std::string> lines;
  if (std::ifstream in(path); in) {
    std::string first;
    std::getline(in, first);
    if (first != header)
      throw std::runtime_error(path + " has other columns (an older format?): move it away to start it anew");
    for (std::string line; std::getline(in, line);)
      if (!line.empty() && !replaced.count(row_key(line))) lines.push_back(line);
  }
  lines.insert(lines.end(), new_lines.begin(), new_lines.end());
  const std::string temporary = path + ".tmp";
  {
    std::ofstream out(temporary);
    out << header << "\n";
    for (const std::string& line : lines) out << line << "\n";
    if (!out.flush()) throw std::runtime_error("cannot write " + temporary);
  }
  fs::rename(temporary, path);
  return lines;
}

std::string key_fields(const Row& row) {
  return std::to_string(row.points) + "," + csv_number(row.sigma_m) + "," + row.pairs + "," + std::to_string(row.seeds);
}

std::string rows_header() {
  std::string header = "points,sigma_m,pairs,seeds,measured";
  for (const Column& c : kColumns) header += std::string(",") + c.name;
  for (const char* stage : kStages) header += std::string(",") + stage + "_median_s";
  return header;
}

std::string to_csv(const Row& row) {
  std::string line = key_fields(row) + "," + row.measured;
  for (const Column& c : kColumns) line += "," + csv_number(row.*c.field);
  for (double s : row.stage_median_s) line += "," + csv_number(s);
  return line;
}

Row row_from_csv(const std::string& line) {
  const auto f = split_csv(line);
  if (f.size() != 5 + std::size(kColumns) + kStages.size()) throw std::runtime_error("malformed row: " + line);
  Row row;
  row.points = std::stoull(f[0]);
  row.sigma_m = std::stod(f[1]);
  row.pairs = f[2];
  row.seeds = std::stoi(f[3]);
  row.measured = f[4];
  std::size_t i = 5;
  for (const Column& c : kColumns) row.*c.field = std::stod(f[i++]);
  for (double& s : row.stage_median_s) s = std::stod(f[i++]);
  return row;
}

std::string runs_header() {
  std::string header = "points,sigma_m,pairs,seeds,source,target,seed,ok,success_coarse,success_final,"
                       "source_keypoints,target_keypoints";
  for (const char* when : {"coarse", "final"})
    for (const char* m : {"mae_deg", "mte_m", "rotation_deg", "translation_m", "rmse_m"})
      header += std::string(",") + when + "_" + m;
  for (const char* stage : kStages) header += std::string(",") + stage + "_s";
  return header + ",total_s,error";
}

std::string to_csv(const Row& row, const Run& r) {
  std::string error = r.error;  // plain CSV: no commas, quotes or line breaks inside a field
  std::replace(error.begin(), error.end(), ',', ';');
  std::replace(error.begin(), error.end(), '"', '\'');
  std::replace(error.begin(), error.end(), '\n', ' ');
  std::ostringstream line;
  line << key_fields(row) << "," << r.pair.source << "," << r.pair.target << "," << r.seed << "," << r.ok << ","
       << r.success_coarse << "," << r.success_final << "," << r.source_keypoints << "," << r.target_keypoints;
  for (const TransformError* e : {&r.coarse, &r.final})
    line << "," << e->mae_deg << "," << e->mte_m << "," << e->rotation_deg << "," << e->translation_m << "," << e->rmse_m;
  for (double s : r.stage_s) line << "," << s;
  line << "," << r.total_s << "," << error;
  return line.str();
}

// ---- the markdown block ----

std::string paper_cell(const Row& row, bool keypoints) {
  for (const PaperCell& p : kPaperTable2)
    if (p.points == row.points && std::abs(p.sigma_mm - row.sigma_m * 1000.0) < 1e-6)
      return " (" + (keypoints ? std::to_string(p.kp) : std::to_string(p.sr) + " %") + ")";
  return "";
}

std::string row_command(const Row& row) {
  std::string pairs = row.pairs;
  std::replace(pairs.begin(), pairs.end(), ' ', ',');
  return "k4reg-bench-table2 --sizes " + std::to_string(row.points) + " --sigmas " + csv_number(row.sigma_m) +
         (row.pairs == "all" ? "" : " --pairs " + pairs) + " --seeds " + std::to_string(row.seeds);
}

std::string markdown(std::vector<Row> rows, const std::string& results_in_markdown, const sim::Scene& scene) {
  std::sort(rows.begin(), rows.end(), [](const Row& a, const Row& b) {
    if (a.points != b.points) return a.points < b.points;
    if (a.sigma_m != b.sigma_m) return a.sigma_m > b.sigma_m;  // the paper lists the largest scale first
    if (a.full_design() != b.full_design()) return a.full_design();
    return a.pairs + std::to_string(a.seeds) < b.pairs + std::to_string(b.seeds);
  });
  const RegistrationParams d = table2_params(0.05, 1, 0);
  const std::size_t full_pairs = all_pairs(static_cast<int>(scene.stations.size())).size();
  std::ostringstream md;
  md << "### Keypoints, success rate, accuracy and time per stage (generated)\n\n"
     << "Generated by `k4reg-bench-table2` (bench/table2.cpp) from `" << results_in_markdown
     << "/table2-rows.csv` (one line per row; every registration in `" << results_in_markdown
     << "/table2-runs.csv`).\n\n"
     << "- Scene: the simulator's `" << kScene << "` (" << scene.description << "), " << scene.stations.size()
     << " stations; each scan simulated once per (station, size) with seed station + 1 and cached on disk "
        "(the same files as `k4reg-bench-compare`).\n"
     << "- One configuration for every run: `register_clouds` with RegistrationParams' defaults (the paper's "
        "Tab. 1: " << d.octaves << " octaves × " << d.scales_per_octave << " scales, minimum contrast "
     << d.min_contrast * 100 << " % of the signal's range, signal auto (intensity), L from the overlap, "
     << d.hypotheses_kept << " hypotheses re-scored by the symmetry guard, free-space check auto, ICP up to "
     << d.icp_max_iterations << " iterations, no time budget) and min_scale_m = σ, overlap = " << kOverlap
     << ", seed = 1 … seeds; in-process, one registration at a time on all cores unless `--threads` says otherwise.\n"
     << "- SR: share of all runs (pairs × seeds; a run ending in an error counts as a failure) whose RMSE against "
        "the ground truth is under " << kIndoorSuccessRmse_m << " m (the paper's indoor threshold, "
        "`kIndoorSuccessRmse_m`), for the coarse result (best hypothesis after the symmetry guard, as in the "
        "paper) and after the final ICP. RMSE: median over the runs that succeeded after ICP. KP: mean keypoints "
        "per scan over the runs (paper values in parentheses: real Z+F scans, so compare trends, not digits).\n"
     << "- Stage times and end-to-end: median seconds (end-to-end also p90) of `register_clouds` from the two "
        "loaded clouds to the final transform (file reading excluded; errors included in end-to-end). Peak RSS: "
        "this process's VmHWM during the row (reset at the row's start), clouds included.\n"
     << "- **Shared machine:** these runs share the 2 cores with other engineers' builds and tests (1-minute "
        "load average at each row's start → end in the last column), so absolute times are pessimistic and noisy.\n\n"
     << "| S | σ | pairs × seeds | KP source / target (paper) | SR coarse (paper) | SR after ICP | RMSE after ICP m |";
  for (const char* stage : kStages) md << " " << stage << " s |";
  md << " end-to-end s median / p90 | peak RSS MB | measured |\n|";
  for (std::size_t i = 0; i < 10 + kStages.size(); ++i) md << "---|";
  md << "\n";
  for (const Row& r : rows) {
    md << "| " << size_label(r.points) << " | " << sigma_label(r.sigma_m) << " | "
       << (r.pairs == "all" ? "all " + std::to_string(static_cast<int>(r.pair_count)) : r.pairs) << " × " << r.seeds
       << (r.errors > 0 ? fmt(" (%.0f errors)", r.errors) : "") << (r.full_design() ? "" : " (subset)") << " | "
       << number(r.source_keypoints, "%.0f") << " / " << number(r.target_keypoints, "%.0f") << paper_cell(r, true)
       << " | " << percent(r.sr_coarse) << paper_cell(r, false) << " | " << percent(r.sr_final) << " | "
       << metres(r.rmse_final_median_m) << " |";
    for (double s : r.stage_median_s) md << " " << seconds(s) << " |";
    md << " " << seconds(r.total_median_s) << " / " << seconds(r.total_p90_s) << " | " << number(r.peak_rss_mb, "%.0f")
       << " | " << r.measured << ", load " << fmt("%.1f", r.load_average) << " → " << number(r.load_average_end, "%.1f")
       << ", " << fmt("%.0f", r.threads)
       << " threads, took " << seconds(r.duration_s / 60.0) << " min |\n";
  }
  std::vector<std::string> measured, pending;
  for (std::size_t points : kFullSizes)
    for (auto sigma = kFullSigmas_m.rbegin(); sigma != kFullSigmas_m.rend(); ++sigma) {
      const bool done = std::any_of(rows.begin(), rows.end(), [&](const Row& r) {
        return r.full_design() && r.points == points && r.sigma_m == *sigma;
      });
      (done ? measured : pending).push_back(size_label(points) + " σ " + sigma_label(*sigma));
    }
  const auto list = [](const std::vector<std::string>& v) {
    std::string text;
    for (const std::string& s : v) text += (text.empty() ? "" : ", ") + s;
    return text.empty() ? std::string("none") : text;
  };
  md << "\nMeasured with the full design (all " << full_pairs << " pairs × " << kFullSeeds
     << " seeds): " << list(measured) << ". ";
  if (pending.empty())
    md << "The full grid is complete.\n";
  else
    md << "**Pending** (not measured with the full design; rows marked \"subset\" used fewer pairs or seeds and "
          "stand in only as a first look): "
       << list(pending) << ". The full grid: `bench/run.sh --table2` (runs `k4reg-bench-table2` with its defaults: "
       << kFullSizes.size() * kFullSigmas_m.size() << " rows × " << full_pairs * kFullSeeds
       << " registrations, hours on 2 cores; it can be run row by row with `--sizes` and `--sigmas`).\n";
  md << "\nA row is reproduced by `k4reg-bench-table2 --sizes S --sigmas σ [--pairs A-B,…] --seeds N`; e.g. the first: `"
     << (rows.empty() ? std::string("k4reg-bench-table2 --quick") : row_command(rows.front())) << "`.\n";
  return md.str();
}

// ---- the run ----

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  char buffer[64];
  std::strftime(buffer, sizeof buffer, "%Y-%m-%d %H:%M UTC", std::gmtime(&t));
  return buffer;
}

double load_average() {
  double load[1] = {0.0};
  return getloadavg(load, 1) == 1 ? load[0] : kNan;
}

void print_run(const Run& r, const Row& row, std::size_t done, std::size_t total, double elapsed_s) {
  std::printf("[%zu/%zu %s] %s σ=%s %d-%d seed %d: ", done, total, clock_text(elapsed_s).c_str(),
              size_label(row.points).c_str(), sigma_label(row.sigma_m).c_str(), r.pair.source, r.pair.target, r.seed);
  if (r.ok)
    std::printf("%s RMSE coarse %.4g m, final %.4g m, rotation %.2f deg, %zu/%zu keypoints, %.2f s\n",
                r.success_coarse ? "OK  " : "FAIL", r.coarse.rmse_m, r.final.rmse_m, r.coarse.rotation_deg,
                r.source_keypoints, r.target_keypoints, r.total_s);
  else
    std::printf("ERROR %s (%.2f s)\n", r.error.c_str(), r.total_s);
  std::fflush(stdout);
}

void run_table2(const Options& o) {
  const sim::Scene scene = sim::make_scene(kScene);
  const int stations = static_cast<int>(scene.stations.size());
  const std::vector<StationPair> pairs = parse_pairs(o.pairs, stations);
  std::set<int> used;
  for (const StationPair& p : pairs) used.insert(p.source), used.insert(p.target);
  fs::create_directories(o.results_dir);
  const std::string rows_csv = o.results_dir + "/table2-rows.csv", runs_csv = o.results_dir + "/table2-runs.csv";
  const std::string results_in_markdown = path_from_markdown(o.markdown, o.results_dir);

  const auto start = Clock::now();
  const auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  const std::size_t total = o.sizes.size() * o.sigmas_m.size() * pairs.size() * o.seeds;
  std::size_t done = 0;
  std::string table;
  for (std::size_t points : o.sizes) {
    std::map<int, CachedScan> scans;  // simulated (or found in the cache) before any row measures memory
    for (int station : used) scans[station] = cached_simulated_scan(o.cache_dir, kScene, station, points);
    for (double sigma : o.sigmas_m) {
      Row row;
      row.points = points, row.sigma_m = sigma, row.pairs = pairs_key(pairs, stations), row.seeds = o.seeds;
      row.measured = utc_now();
      row.pair_count = pairs.size();
      row.threads = o.threads > 0 ? o.threads : std::thread::hardware_concurrency();
      row.load_average = load_average();
      const auto row_start = Clock::now();
      reset_peak_rss();
      std::vector<Run> runs;
      std::vector<double> read_s;
      for (const StationPair& pair : pairs) {
        const auto read_start = Clock::now();
        const PointCloud source = read_cloud(scans.at(pair.source).path), target = read_cloud(scans.at(pair.target).path);
        read_s.push_back(std::chrono::duration<double>(Clock::now() - read_start).count());
        const Eigen::Matrix4d truth = source_to_target_truth(scans.at(pair.source), scans.at(pair.target));
        for (int seed = 1; seed <= o.seeds; ++seed) {
          runs.push_back(register_pair(source, target, truth, pair, sigma, seed, o.threads));
          print_run(runs.back(), row, ++done, total, elapsed());
        }
      }
      row.peak_rss_mb = peak_rss_mb();
      row.load_average_end = load_average();
      row.duration_s = std::chrono::duration<double>(Clock::now() - row_start).count();
      row.read_median_s = median(read_s);
      summarise(runs, row);

      std::vector<std::string> run_lines;
      for (const Run& r : runs) run_lines.push_back(to_csv(row, r));
      merge_csv(runs_csv, runs_header(), run_lines);
      std::vector<Row> all;
      for (const std::string& line : merge_csv(rows_csv, rows_header(), {to_csv(row)})) all.push_back(row_from_csv(line));
      table = markdown(all, results_in_markdown, scene);
      replace_block(o.markdown, "table2", table);
      std::printf("row %s σ=%s done: SR %.0f %% coarse, %.0f %% after ICP; %s and %s updated\n",
                  size_label(points).c_str(), sigma_label(sigma).c_str(), 100 * row.sr_coarse, 100 * row.sr_final,
                  rows_csv.c_str(), o.markdown.c_str());
    }
  }
  std::printf("\n%s\nk4reg-bench-table2: %zu registrations in %s\n", table.c_str(), total, clock_text(elapsed()).c_str());
}

}  // namespace
}  // namespace k4reg::bench

int main(int argc, char** argv) {
  k4reg::bench::Options o;
  CLI::App app{"The paper's Table 2 for k4reg's K-4PCS on the simulated indoor lab"};
  CLI::Option* quick = app.add_flag("--quick", o.quick, "0.7M points, σ 0.05 m, all 15 pairs, 10 seeds");
  app.add_option("--sizes", o.sizes, "points per scan")->delimiter(',')->check(CLI::Range(1000, 50000000))
      ->capture_default_str()->excludes(quick);
  app.add_option("--sigmas", o.sigmas_m, "minimum scales σ in metres")->delimiter(',')->check(CLI::Range(0.001, 10.0))
      ->capture_default_str()->excludes(quick);
  app.add_option("--pairs", o.pairs, "station pairs SOURCE-TARGET, comma-separated (default: all 15)")->excludes(quick);
  app.add_option("--seeds", o.seeds, "registration seeds per pair (1 … N)")->check(CLI::Range(1, 1000))
      ->capture_default_str()->excludes(quick);
  app.add_option("--threads", o.threads, "threads per registration (0 = all cores)")->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--cache-dir", o.cache_dir, "simulated scans are cached here (shared with k4reg-bench-compare)")
      ->capture_default_str();
  app.add_option("--results-dir", o.results_dir, "table2-rows.csv and table2-runs.csv go here")->capture_default_str();
  app.add_option("--markdown", o.markdown, "file whose table2 block is rebuilt")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  if (o.quick) o.sizes = {700000}, o.sigmas_m = {0.05}, o.pairs.clear(), o.seeds = k4reg::bench::kFullSeeds;
  try {
    k4reg::bench::run_table2(o);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "k4reg-bench-table2: %s\n", e.what());
    return 1;
  }
}
