#include "compare_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>

#include "paper_tables.h"
#include "statistics.h"
#include "table_format.h"

namespace k4reg::bench {
namespace {

const char* method_label(const std::string& method) {
  if (method == kOursK4pcs) return "K-4PCS k4reg";
  if (method == kPclK4pcs) return "K-4PCS PCL";
  if (method == kOursPlain) return "4PCS k4reg";
  if (method == kPclPlain) return "4PCS PCL";
  if (method == kOursMatch) return "4PCS stage k4reg";
  if (method == kPclMatch) return "KFPCS stage PCL";
  if (method == kPclSacIa) return "FPFH + SAC-IA PCL";
  if (method == kOpen3dRansac) return "FPFH + RANSAC Open3D";
  if (method == kOpen3dFgr) return "FPFH + FGR Open3D";
  return "?";
}

bool is_ours(const std::string& method) { return method == kOursK4pcs || method == kOursPlain || method == kOursMatch; }

// All runs of one method on one (suite, size, sigma): one line of the tables.
struct Row {
  std::size_t suite = 0, points = 0;
  double sigma_m = 0;
  std::string method;
  std::vector<const Run*> runs;
  std::set<std::size_t> cases;

  std::vector<double> collect(const std::function<double(const Run&)>& f, bool only_ok = true) const {
    std::vector<double> v;
    for (const Run* r : runs)
      if (!only_ok || r->ok) v.push_back(f(*r));
    return v;
  }
  double success_rate(bool final) const {
    if (runs.empty()) return kNan;
    std::size_t hits = 0;
    for (const Run* r : runs) hits += final ? r->success_final : r->success_coarse;
    return double(hits) / runs.size();
  }
  std::size_t count(const std::function<bool(const Run&)>& f) const {
    return std::count_if(runs.begin(), runs.end(), [&](const Run* r) { return f(*r); });
  }
  std::string time_cell() const {
    const auto t = collect([](const Run& r) { return r.total_s; });
    if (t.empty()) return "–";
    return seconds(median(t)) + " (" + seconds(minimum(t)) + "–" + seconds(maximum(t)) + ")";
  }
  double stage_median(const std::string& stage) const {
    std::vector<double> v;
    for (const Run* r : runs)
      if (r->ok && r->stages.count(stage)) v.push_back(r->stages.at(stage));
    return median(v);
  }
  std::vector<std::string> stage_names() const {
    std::vector<std::string> names;
    for (const Run* r : runs)
      for (const auto& [stage, s] : r->stages)
        if (std::find(names.begin(), names.end(), stage) == names.end()) names.push_back(stage);
    return names;
  }
};

// Keypoints per scan (mean of source and target): from the keypoint job for the detectors (seed-free),
// from the runs for the plain grids and the given keypoints.
double keypoints(const Row& row, const Report& report) {
  std::vector<double> v;
  if (row.method == kOursK4pcs || row.method == kPclK4pcs) {
    for (std::size_t c : row.cases) {
      const DetectorStats& d = row.method == kOursK4pcs ? report.keypoints[c].ours : report.keypoints[c].pcl;
      if (d.ok) v.push_back(0.5 * (d.source + d.target));
    }
  } else {
    for (const Run* r : row.runs)
      if (r->source_keypoints > 0) v.push_back(0.5 * (r->source_keypoints + r->target_keypoints));
  }
  return mean(v);
}

// Largest peak RSS of the row's processes (runs that were not started have none).
double peak_rss_mb(const Row& row) {
  std::vector<double> v;
  for (const Run* r : row.runs)
    if (r->peak_rss_mb > 0) v.push_back(r->peak_rss_mb);
  return maximum(v);
}

double repeatability(const Row& row, const Report& report) {
  if (row.method != kOursK4pcs && row.method != kPclK4pcs) return kNan;
  std::vector<double> v;
  for (std::size_t c : row.cases) {
    const DetectorStats& d = row.method == kOursK4pcs ? report.keypoints[c].ours : report.keypoints[c].pcl;
    if (d.ok) v.push_back(d.repeatability);
  }
  return mean(v);
}

double plain_spacing(const Row& row, const Report& report) {
  std::vector<double> v;
  for (std::size_t c : row.cases)
    if (report.keypoints[c].plain_voxel_m > 0) v.push_back(report.keypoints[c].plain_voxel_m);
  return median(v);
}

std::vector<Row> make_rows(const Report& report) {
  std::vector<Row> rows;
  for (const Run& run : report.runs) {
    const Case& c = report.cases[run.case_index];
    auto it = std::find_if(rows.begin(), rows.end(), [&](const Row& r) {
      return r.suite == c.suite && r.points == c.points && r.sigma_m == c.job.sigma_m && r.method == run.method;
    });
    if (it == rows.end()) {
      rows.push_back(Row{c.suite, c.points, c.job.sigma_m, run.method, {}, {}});
      it = rows.end() - 1;
    }
    it->runs.push_back(&run);
    it->cases.insert(run.case_index);
  }
  return rows;
}

const Row* find_row(const std::vector<Row>& rows, std::size_t suite, std::size_t points, double sigma_m,
                    const std::string& method) {
  for (const Row& r : rows)
    if (r.suite == suite && r.points == points && std::abs(r.sigma_m - sigma_m) < 1e-9 && r.method == method) return &r;
  return nullptr;
}

// Runs the configuration asks for in this row (0 when unknown).
std::size_t planned_runs(const Row& row, const Report& report) {
  const auto it = report.planned.find({row.suite, row.points, row.sigma_m, row.method});
  return it == report.planned.end() ? 0 : it->second;
}

// A row of a report made before the comparison finished, with only some of its runs.
bool partial(const Row& row, const Report& report) { return row.runs.size() < planned_runs(row, report); }

std::string runs_cell(const Row& row, const Report& report) {
  return std::to_string(row.runs.size()) +
         (partial(row, report) ? " of " + std::to_string(planned_runs(row, report)) + " ‡" : "");
}

// "SR" cell: coarse success rate, with a dagger when some runs hit the wall-time cap and a double dagger
// when the row is still partial.
std::string sr_cell(const Row* row, const Report& report) {
  if (!row) return "–";
  const std::size_t capped = row->count([](const Run& r) { return r.capped; });
  return percent(row->success_rate(false)) + (capped ? "†" : "") + (partial(*row, report) ? "‡" : "");
}

std::string rmse_cell(const Row* row) {
  return row ? metres(median(row->collect([](const Run& r) { return r.coarse.rmse_m; }))) : "–";
}

std::string time_median_cell(const Row* row) {
  return row ? seconds(median(row->collect([](const Run& r) { return r.total_s; }))) : "–";
}

std::size_t suite_index(const Report& report, const std::string& name) {
  for (std::size_t i = 0; i < report.suites.size(); ++i)
    if (report.suites[i].name == name) return i;
  return report.suites.size();
}

std::vector<double> sigmas_of(const Suite& suite) {
  std::vector<double> s = suite.sigmas_m;
  std::sort(s.rbegin(), s.rend());  // the paper lists the largest scale first
  return s;
}

// ---- markdown sections ----

// Every system on one suite (issue 49): success as SR counts it (the coarse result against the suite's
// threshold), the median T per pair, and that median over k4reg's on the same pairs (the plain baselines run on a
// few pairs only). k4reg is K-4PCS, or its 4PCS stage where the keypoints are given.
void summary_section(std::ostringstream& md, const Report& report) {
  md << "#### Summary: every system per suite\n\n"
     << "| suite | system | success / runs | T s per pair, median | T / k4reg T, same pairs |\n|---|---|---|---|---|\n";
  for (std::size_t suite = 0; suite < report.suites.size(); ++suite) {
    std::vector<Row> systems;  // in the order they take turns
    for (const Run& run : report.runs) {
      if (report.cases[run.case_index].suite != suite) continue;
      auto it = std::find_if(systems.begin(), systems.end(), [&](const Row& r) { return r.method == run.method; });
      if (it == systems.end()) it = systems.insert(systems.end(), Row{suite, 0, 0, run.method, {}, {}});
      it->runs.push_back(&run);
      it->cases.insert(run.case_index);
    }
    const std::string reference = report.suites[suite].keypoints_given ? kOursMatch : kOursK4pcs;
    const auto k4reg =
        std::find_if(systems.begin(), systems.end(), [&](const Row& r) { return r.method == reference; });
    for (const Row& row : systems) {
      const std::size_t hits = row.count([](const Run& r) { return r.success_coarse; });
      const std::size_t capped = row.count([](const Run& r) { return r.capped; });
      const double t = median(row.collect([](const Run& r) { return r.total_s; }));
      std::string ratio = "–";
      if (row.method == reference) {
        ratio = "(reference)";
      } else if (k4reg != systems.end()) {
        std::set<std::pair<std::size_t, int>> runs;  // (case, trial)
        for (const Run* r : row.runs) runs.insert({r->case_index, r->trial});
        std::vector<double> k4reg_t;
        for (const Run* r : k4reg->runs)
          if (r->ok && runs.count({r->case_index, r->trial})) k4reg_t.push_back(r->total_s);
        if (median(k4reg_t) > 0) ratio = fmt("%.1f×", t / median(k4reg_t));
      }
      md << "| " << report.suites[suite].name << " | " << method_label(row.method) << " | " << hits << " / "
         << runs_cell(row, report) << (capped ? fmt(" (%.0f over the cap)", capped) : "") << " | " << seconds(t)
         << " | " << ratio << " |\n";
    }
  }
  md << "\nSuccess: the coarse result within the suite's threshold (as SR below; k4reg's coarse result has had "
        "its short ICP settles, the peers get no ICP). T: seconds from the two loaded clouds to the transform, the "
        "method's own preprocessing (voxel grid, keypoints or features) included, file reading and handing the clouds "
        "to PCL or Open3D not (see below); medians over the runs that returned a transform. T / k4reg T: over the "
        "same pairs and trials.\n\n";
  for (const auto& [method, reason] : report.skipped_methods)
    md << "- Not run: " << method_label(method) << " (`" << method << "`): " << reason << ".\n";
  if (!report.skipped_methods.empty()) md << "\n";
}

void configuration_section(std::ostringstream& md, const Report& report) {
  md << "**Configuration** (one per suite, the same for every pair; no per-pair tuning):\n\n"
     << "| suite | data | pairs | σ | overlap | success | trials | plain 4PCS | k4reg bases | PCL iterations "
        "| wall cap |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Suite& s : report.suites) {
    std::string sigmas, sizes;
    for (double sigma : s.sigmas_m) sigmas += (sigmas.empty() ? "" : ", ") + sigma_label(sigma);
    for (std::size_t n : s.sizes) sizes += (sizes.empty() ? " at " : ", ") + size_label(n);
    const std::string success = s.max_rotation_deg > 0
                                    ? fmt("≤ %g°", s.max_rotation_deg) + fmt(" and ≤ %g m", s.max_translation_m)
                                    : "RMSE < " + metres(s.success_rmse_m) + " m";
    std::string baseline = "no";
    if (s.baseline) {
      baseline = s.baseline_size ? "at " + size_label(s.baseline_size) + ", " : std::string();
      if (s.baseline_sigma_m > 0) baseline += "σ " + sigma_label(s.baseline_sigma_m) + ", ";
      for (const std::string& pair : s.baseline_pairs) baseline += pair + ", ";
      const int trials = s.baseline_trials ? s.baseline_trials : s.trials;
      baseline += std::to_string(trials) + (trials == 1 ? " trial" : " trials");
    }
    md << "| " << s.name << " | " << s.data << sizes << " | " << s.pairs << " | " << sigmas << " | " << s.overlap
       << " | " << success << " | " << s.trials << " | " << baseline << " | "
       << (s.max_bases ? std::to_string(s.max_bases) : "auto") << " | " << s.pcl_iterations << " | " << s.cap_s
       << " s |\n";
  }
  md << "\n";
}

void table2(std::ostringstream& md, const Report& report, const std::vector<Row>& rows) {
  const std::size_t lab = suite_index(report, "lab");
  if (lab == report.suites.size()) return;
  const Suite& suite = report.suites[lab];
  md << "#### Table 2 – indoor lab (simulated): keypoints per scan (KP) and success rate (SR), k4reg / PCL (paper)\n\n"
     << "| σ |";
  for (std::size_t n : suite.sizes) md << " S = " << size_label(n) << " KP | SR |";
  md << "\n|---|";
  for (std::size_t i = 0; i < suite.sizes.size(); ++i) md << "---|---|";
  md << "\n";
  for (double sigma : sigmas_of(suite)) {
    md << "| " << sigma_label(sigma) << " |";
    for (std::size_t n : suite.sizes) {
      const Row* ours = find_row(rows, lab, n, sigma, kOursK4pcs);
      const Row* pcl = find_row(rows, lab, n, sigma, kPclK4pcs);
      std::string paper_kp = "–", paper_sr = "–";
      for (const PaperCell& p : kPaperTable2)
        if (std::abs(p.sigma_mm - sigma * 1000) < 1e-6 && p.points == n)
          paper_kp = std::to_string(p.kp), paper_sr = std::to_string(p.sr) + " %";
      md << " " << number(ours ? keypoints(*ours, report) : kNan, "%.0f") << " / "
         << number(pcl ? keypoints(*pcl, report) : kNan, "%.0f") << " (" << paper_kp << ") | " << sr_cell(ours, report) << " / "
         << sr_cell(pcl, report) << " (" << paper_sr << ") |";
    }
    md << "\n";
  }
  md << "\n";
}

// Tables 3 and 4: 4PCS vs K-4PCS, PCL and ours, at one scan size.
void comparison_table(std::ostringstream& md, const Report& report, const std::vector<Row>& rows, const char* title,
                      const std::string& suite_name, std::size_t points, const PaperComparison (&paper)[3]) {
  const std::size_t index = suite_index(report, suite_name);
  if (index == report.suites.size()) return;
  const Suite& suite = report.suites[index];
  if (std::find(suite.sizes.begin(), suite.sizes.end(), points) == suite.sizes.end()) return;
  md << "#### " << title << "\n\n"
     << "| σ (K-4PCS) | 4PCS grid | 4PCS PCL SR | RMSE | T | 4PCS k4reg SR | RMSE | T | K-4PCS PCL SR | RMSE | T | KP "
        "| K-4PCS k4reg SR | RMSE | T | KP | paper 4PCS | paper K-4PCS |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (double sigma : sigmas_of(suite)) {
    const Row* rows4[] = {find_row(rows, index, points, sigma, kPclPlain), find_row(rows, index, points, sigma, kOursPlain),
                          find_row(rows, index, points, sigma, kPclK4pcs), find_row(rows, index, points, sigma, kOursK4pcs)};
    const Row* any = rows4[3] ? rows4[3] : rows4[2] ? rows4[2] : rows4[1] ? rows4[1] : rows4[0];
    md << "| " << sigma_label(sigma) << " | " << (any ? metres(plain_spacing(*any, report)) + " m" : "–");
    for (int m = 0; m < 4; ++m) {
      md << " | " << sr_cell(rows4[m], report) << " | " << rmse_cell(rows4[m]) << " | " << time_median_cell(rows4[m]);
      if (m >= 2) md << " | " << number(rows4[m] ? keypoints(*rows4[m], report) : kNan, "%.0f");
    }
    std::string paper4 = "–", paperk = "–";
    for (const PaperComparison& p : paper)
      if (std::abs(p.sigma_mm - sigma * 1000) < 1e-6) paper4 = p.four_pcs, paperk = p.k4pcs;
    md << " | " << paper4 << " | " << paperk << " |\n";
  }
  md << "\nSR and RMSE (median, m) are those of the coarse alignment, as in the paper; T = median seconds from "
        "loaded clouds to the transform (k4reg includes its ICP).\n\n";
}

void real_table(std::ostringstream& md, const Report& report, const std::vector<Row>& rows) {
  md << "#### Real scans with ground truth\n\n"
     << "| data | method | runs | KP | SR | SR after ICP | MAE ° | MTE m | RMSE m | T s median (min–max) | "
        "peak RSS MB | repeatability |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Row& row : rows) {
    if (!report.suites[row.suite].sizes.empty()) continue;
    md << "| " << report.suites[row.suite].name << " | " << method_label(row.method) << " | " << runs_cell(row, report) << " | "
       << number(keypoints(row, report), "%.0f") << " | " << sr_cell(&row, report) << " | "
       << (is_ours(row.method) && row.method != kOursMatch ? percent(row.success_rate(true)) : "–") << " | "
       << number(median(row.collect([](const Run& r) { return r.coarse.mae_deg; })), "%.2f") << " | "
       << metres(median(row.collect([](const Run& r) { return r.coarse.mte_m; }))) << " | "
       << metres(median(row.collect([](const Run& r) { return r.coarse.rmse_m; }))) << " | " << row.time_cell()
       << " | " << number(peak_rss_mb(row), "%.0f") << " | "
       << percent(repeatability(row, report)) << " |\n";
  }
  md << "\nMAE, MTE and RMSE: medians of the coarse result. \"SR after ICP\": the final transform of k4reg's "
        "pipeline (PCL's and Open3D's methods have no refinement stage).\n\n";
}

std::string stage_cell(const Row& row) {
  std::string cell;
  for (const std::string& stage : row.stage_names())
    cell += (cell.empty() ? "" : ", ") + stage + " " + seconds(row.stage_median(stage));
  return cell.empty() ? "–" : cell;
}

// The targets, checked on this run: our K-4PCS end to end (file reading to the final transform,
// ICP included) against PCL's K-4PCS (SIFT + KFPCS, no ICP); on ETH office the 4PCS stages alone.
void targets_section(std::ostringstream& md, const Report& report, const std::vector<Row>& rows) {
  std::vector<double> ratios;
  std::vector<std::string> sr_below_pcl, lab_50mm;
  std::string ten_million;
  std::size_t lower_bounds = 0;
  std::ostringstream table;
  for (const Row& ours : rows) {
    if (ours.method != kOursK4pcs && ours.method != kOursMatch) continue;
    const Row* pcl = find_row(rows, ours.suite, ours.points, ours.sigma_m, ours.method == kOursK4pcs ? kPclK4pcs : kPclMatch);
    const Suite& suite = report.suites[ours.suite];
    const std::string label = suite.name + (ours.points ? " " + size_label(ours.points) : "") + " σ " +
                              sigma_label(ours.sigma_m) + (partial(ours, report) ? " ‡" : "");
    const double ours_s = median(ours.collect([](const Run& r) { return r.read_s + r.total_s; }));
    double pcl_s = kNan;
    bool lower_bound = false;
    if (pcl) {
      const auto t = pcl->collect([](const Run& r) { return r.total_s; });
      lower_bound = t.empty();  // every PCL run passed the cap (or never started): count the cap
      pcl_s = lower_bound ? suite.cap_s : median(t);
      if (!std::isnan(ours_s) && ours_s > 0) ratios.push_back(pcl_s / ours_s), lower_bounds += lower_bound;
      if (ours.success_rate(false) < pcl->success_rate(false)) sr_below_pcl.push_back(label);
    }
    if (suite.name == "lab" && std::abs(ours.sigma_m - 0.05) < 1e-9)
      lab_50mm.push_back(size_label(ours.points) + " " + percent(ours.success_rate(false)));
    if (suite.name == "lab" && ours.points >= 10000000)
      ten_million += "σ " + sigma_label(ours.sigma_m) + ": " + seconds(ours_s) + " s, " +
                     number(peak_rss_mb(ours), "%.0f") + " MB; ";
    table << "| " << label << " | " << percent(ours.success_rate(false)) << " / " << (pcl ? percent(pcl->success_rate(false)) : "–")
          << " | " << seconds(ours_s) << " | " << (lower_bound ? "> " : "") << seconds(pcl_s) << " | "
          << (pcl && ours_s > 0 ? (lower_bound ? "> " : "") + fmt("%.1f×", pcl_s / ours_s) : "–") << " |\n";
  }
  if (ratios.empty()) return;
  const double median_ratio = median(ratios);
  md << "#### Targets (issue 4)\n\n"
     << "- Success rate ≥ PCL K-4PCS on every row: **" << (sr_below_pcl.empty() ? "met" : "not met") << "**";
  for (std::size_t i = 0; i < sr_below_pcl.size(); ++i) md << (i ? ", " : " (below on ") << sr_below_pcl[i];
  md << (sr_below_pcl.empty() ? "" : ")") << ".\n";
  if (!lab_50mm.empty()) {
    md << "- ≥ 98 % on the indoor suite at σ = 50 mm:";
    for (const std::string& cell : lab_50mm) md << " " << cell << ";";
    md << "\n";
  }
  md << "- End to end at least 10× faster than PCL K-4PCS, median over the rows: **" << fmt("%.1f×", median_ratio)
     << " – " << (median_ratio >= 10.0 ? "met" : "not met") << "**"
     << (lower_bounds ? " (" + std::to_string(lower_bounds) + (lower_bounds == 1 ? " row counts" : " rows count") +
                            " PCL at its cap: lower bounds)"
                      : "") << ".\n";
  if (!ten_million.empty())
    md << "- Two 10 M-point scans under 15 s and 3 GB (k4reg end to end, median; largest peak RSS): " << ten_million
       << "\n";
  md << "\n| row | SR k4reg / PCL | k4reg s (read + T, median) | PCL s (T, median) | PCL / k4reg |\n|---|---|---|---|---|\n"
     << table.str() << "\n";
}

void every_row_table(std::ostringstream& md, const Report& report, const std::vector<Row>& rows) {
  md << "#### Every row\n\n"
     << "| suite | S | σ | method | runs | failed / capped | KP | SR coarse | SR final | MAE ° | MTE m | RMSE coarse m "
        "| RMSE final m | stage medians s | T s median (min–max) | read s | peak RSS MB | repeatability |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Row& row : rows) {
    const std::size_t failed = row.count([](const Run& r) { return !r.ok; });
    const std::size_t capped = row.count([](const Run& r) { return r.capped; });
    md << "| " << report.suites[row.suite].name << " | " << size_label(row.points) << " | " << sigma_label(row.sigma_m)
       << " | " << method_label(row.method) << " | " << runs_cell(row, report) << " | " << failed << " / " << capped << " | "
       << number(keypoints(row, report), "%.0f") << " | " << percent(row.success_rate(false)) << " | "
       << percent(row.success_rate(true)) << " | "
       << number(median(row.collect([](const Run& r) { return r.coarse.mae_deg; })), "%.2f") << " | "
       << metres(median(row.collect([](const Run& r) { return r.coarse.mte_m; }))) << " | "
       << metres(median(row.collect([](const Run& r) { return r.coarse.rmse_m; }))) << " | "
       << metres(median(row.collect([](const Run& r) { return r.final.rmse_m; }))) << " | " << stage_cell(row) << " | "
       << row.time_cell() << " | " << seconds(median(row.collect([](const Run& r) { return r.read_s; }))) << " | "
       << number(peak_rss_mb(row), "%.0f") << " | "
       << percent(repeatability(row, report)) << " |\n";
  }
  md << "\n";
}

std::string detector_cells(const DetectorStats& d) {
  if (!d.ok && d.error.starts_with("not run")) return d.error + " | – | – | –";
  if (!d.ok) return "failed: " + d.error + " | – | ≥ " + seconds(d.seconds) + " | " + number(d.peak_rss_mb, "%.0f");
  return std::to_string(d.source) + " / " + std::to_string(d.target) + " | " + percent(d.repeatability) + " | " +
         seconds(d.seconds) + " | " + number(d.peak_rss_mb, "%.0f");
}

void keypoint_table(std::ostringstream& md, const Report& report) {
  md << "#### Keypoint detectors per pair (run once per pair in their own processes; both are deterministic)\n\n"
     << "| suite | S | σ | pair | k4reg KP src / tgt | repeatability | s | MB | PCL SIFT KP src / tgt | repeatability "
        "| s | MB | SIFT octaves over VoxelGrid's limit | voxel overlap under the truth | 4PCS grid m |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < report.cases.size(); ++i) {
    const Case& c = report.cases[i];
    const KeypointStats& k = report.keypoints[i];
    if (!k.ran) continue;
    md << "| " << report.suites[c.suite].name << " | " << size_label(c.points) << " | " << sigma_label(c.job.sigma_m)
       << " | " << c.pair << " | " << detector_cells(k.ours) << " | " << detector_cells(k.pcl) << " | "
       << k.pcl.sift_overflow_octaves << " | " << percent(k.ours.ok ? k.truth_overlap : kNan) << " | "
       << (k.plain_voxel_m > 0 ? metres(k.plain_voxel_m) : "–") << " |\n";
  }
  md << "\nRepeatability: share of source keypoints with a target keypoint within 2σ after the ground truth "
        "(bounded by the overlap). Voxel overlap under the truth: the same measure on the σ voxel grids – a check of "
        "the ground truth and the pair's real overlap. s and MB: both scans, one detector run, peak RSS of that process. SIFT octaves "
        "over the limit: pcl::VoxelGrid refuses grids of more than 2^31 cells and passes the unfiltered cloud on, "
        "so SIFT then works on raw points (slow).\n\n";
}

void failures_section(std::ostringstream& md, const Report& report) {
  std::map<std::string, int> counts;
  for (const Run& r : report.runs)
    if (!r.ok || r.capped)
      ++counts[std::string(method_label(r.method)) + " on " + report.suites[report.cases[r.case_index].suite].name +
               ": " + (r.error.empty() ? "over the wall-time cap" : r.error)];
  if (counts.empty()) return;
  md << "#### Runs without a usable result\n\n";
  for (const auto& [what, n] : counts) md << "- " << n << " × " << what << "\n";
  md << "\n";
}

// ---- CSV and plots ----

std::string csv_escape(const std::string& s) {
  std::string out = "\"";
  for (char ch : s) out += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return out + "\"";
}

// Every stage name any run reported, in first-seen order (the core's stages may change).
std::vector<std::string> all_stages(const Report& report) {
  std::vector<std::string> names;
  for (const Run& r : report.runs)
    for (const auto& [stage, s] : r.stages)
      if (std::find(names.begin(), names.end(), stage) == names.end()) names.push_back(stage);
  return names;
}

void write_runs_csv(const Report& report, const std::string& path) {
  std::ofstream out(path);
  out << "suite,pair,points,sigma_m,method,trial,ok,capped,success_coarse,success_final,"
         "coarse_mae_deg,coarse_mte_m,coarse_rotation_deg,coarse_translation_m,coarse_rmse_m,"
         "final_mae_deg,final_mte_m,final_rotation_deg,final_translation_m,final_rmse_m,"
         "source_keypoints,target_keypoints,read_s,convert_s,total_s";
  const std::vector<std::string> stages = all_stages(report);
  for (const std::string& stage : stages) out << "," << stage << "_s";
  out << ",peak_rss_mb,sift_overflow_octaves,error\n";
  for (const Run& r : report.runs) {
    const Case& c = report.cases[r.case_index];
    out << report.suites[c.suite].name << "," << c.pair << "," << c.points << "," << c.job.sigma_m << "," << r.method
        << "," << r.trial << "," << r.ok << "," << r.capped << "," << r.success_coarse << "," << r.success_final;
    for (const Errors* e : {&r.coarse, &r.final})
      out << "," << e->mae_deg << "," << e->mte_m << "," << e->rotation_deg << "," << e->translation_m << "," << e->rmse_m;
    out << "," << r.source_keypoints << "," << r.target_keypoints << "," << r.read_s << "," << r.convert_s << ","
        << r.total_s;
    for (const std::string& stage : stages) out << "," << (r.stages.count(stage) ? fmt("%.4f", r.stages.at(stage)) : "");
    out << "," << r.peak_rss_mb << "," << r.sift_overflow_octaves << "," << csv_escape(r.error) << "\n";
  }
}

void write_rows_csv(const Report& report, const std::vector<Row>& rows, const std::string& path) {
  std::ofstream out(path);
  out << "suite,points,sigma_m,method,runs,planned_runs,failed,capped,keypoints,sr_coarse,sr_final,mae_deg,mte_m,rmse_coarse_m,"
         "rmse_final_m,total_median_s,total_min_s,total_max_s,read_median_s";
  const std::vector<std::string> stages = all_stages(report);
  for (const std::string& stage : stages) out << "," << stage << "_median_s";
  out << ",peak_rss_max_mb,repeatability,plain_voxel_m\n";
  for (const Row& row : rows) {
    const auto total = row.collect([](const Run& r) { return r.total_s; });
    out << report.suites[row.suite].name << "," << row.points << "," << row.sigma_m << "," << row.method << ","
        << row.runs.size() << "," << planned_runs(row, report) << "," << row.count([](const Run& r) { return !r.ok; })
        << "," << row.count([](const Run& r) { return r.capped; }) << "," << keypoints(row, report) << ","
        << row.success_rate(false) << "," << row.success_rate(true) << ","
        << median(row.collect([](const Run& r) { return r.coarse.mae_deg; })) << ","
        << median(row.collect([](const Run& r) { return r.coarse.mte_m; })) << ","
        << median(row.collect([](const Run& r) { return r.coarse.rmse_m; })) << ","
        << median(row.collect([](const Run& r) { return r.final.rmse_m; })) << "," << median(total) << ","
        << minimum(total) << "," << maximum(total) << ","
        << median(row.collect([](const Run& r) { return r.read_s; }));
    for (const std::string& stage : stages) out << "," << row.stage_median(stage);
    out << "," << peak_rss_mb(row) << ","
        << repeatability(row, report) << "," << plain_spacing(row, report) << "\n";
  }
}

// A self-contained gnuplot script (data inline) writing <stem>.png next to itself.
struct Series {
  std::string title;
  std::vector<std::vector<double>> points;  // x, y[, ylow, yhigh]
};

void write_plot(const std::string& path, const std::string& png, const std::string& settings,
                const std::vector<Series>& series, const char* style) {
  std::ofstream out(path);
  out << "# Generated by k4reg-bench-compare; run `gnuplot " << std::filesystem::path(path).filename().string()
      << "` in this folder.\nset terminal pngcairo size 900,600 noenhanced font 'sans,11'\nset output '" << png
      << "'\nset key outside right\nset grid\n"
      << settings;
  for (std::size_t i = 0; i < series.size(); ++i) {
    out << "$d" << i << " << EOD\n";
    for (const auto& p : series[i].points) {
      for (double v : p) out << v << " ";
      out << "\n";
    }
    out << "EOD\n";
  }
  out << "plot ";
  for (std::size_t i = 0; i < series.size(); ++i)
    out << (i ? ", \\\n     " : "") << "$d" << i << " " << style << " pt " << 5 + 2 * (i % 5) << " ps 1.5 title '"
        << series[i].title << "'";
  out << (series.empty() ? "NaN notitle" : "") << "\n";
}

void write_plots(const Report& report, const std::vector<Row>& rows, const std::string& dir,
                 const std::string& stem) {
  const std::size_t lab = suite_index(report, "lab");
  if (lab == report.suites.size()) return;
  const Suite& suite = report.suites[lab];
  std::vector<Series> sr, time;
  for (const char* method : {kOursK4pcs, kPclK4pcs}) {
    for (std::size_t n : suite.sizes) {
      Series s{std::string(method_label(method)) + " " + size_label(n), {}};
      for (double sigma : suite.sigmas_m)
        if (const Row* row = find_row(rows, lab, n, sigma, method))
          s.points.push_back({sigma * 1000.0, 100.0 * row->success_rate(false)});
      std::sort(s.points.begin(), s.points.end());
      if (!s.points.empty()) sr.push_back(s);
    }
    for (double sigma : suite.sigmas_m) {
      Series s{std::string(method_label(method)) + " σ " + sigma_label(sigma), {}};
      for (std::size_t n : suite.sizes)
        if (const Row* row = find_row(rows, lab, n, sigma, method)) {
          const auto t = row->collect([](const Run& r) { return r.total_s; });
          if (!t.empty()) s.points.push_back({n / 1e6, median(t), minimum(t), maximum(t)});
        }
      if (!s.points.empty()) time.push_back(s);
    }
  }
  write_plot(dir + "/" + stem + "-sr-vs-sigma.gp", stem + "-sr-vs-sigma.png",
             "set title 'Indoor lab (simulated): coarse success rate vs minimum scale'\n"
             "set xlabel 'minimum DoG scale sigma (mm)'\nset ylabel 'success rate (%)'\n"
             "set logscale x 2\nset xrange [20:120]\nset yrange [0:105]\nset xtics (25, 50, 100)\n",
             sr, "with linespoints lw 2");
  write_plot(dir + "/" + stem + "-time-vs-size.gp", stem + "-time-vs-size.png",
             "set title 'Indoor lab (simulated): time per pair vs scan size (median, bars min-max)'\n"
             "set xlabel 'points per scan (millions)'\nset ylabel 'seconds'\nset logscale xy\n"
             "set xrange [0.5:14]\nset xtics (0.7, 2.5, 10)\n",
             time, "with yerrorlines lw 2");
}

}  // namespace

void write_outputs(const Report& report, const std::string& dir) {
  std::filesystem::create_directories(dir);
  const std::vector<Row> rows = make_rows(report);
  const std::string stem = "compare-" + report.mode;
  write_runs_csv(report, dir + "/" + stem + "-runs.csv");
  write_rows_csv(report, rows, dir + "/" + stem + "-rows.csv");
  write_plots(report, rows, dir, stem);
}

std::string markdown(const Report& report, const std::string& results_dir_in_repo) {
  const std::vector<Row> rows = make_rows(report);
  const std::string stem = results_dir_in_repo + "/compare-" + report.mode;
  std::ostringstream md;
  md << "### K-4PCS and 4PCS: k4reg vs PCL 1.13, beside FPFH peers (PCL, Open3D 0.16) (" << report.mode << " run)\n\n"
     << "Started " << report.started << ", took " << seconds(report.duration_s / 60.0) << " min of machine time"
     << (report.sessions > 1 ? " in " + std::to_string(report.sessions) + " sessions (resumed with --resume)" : "")
     << ". Command: `" << report.command << "`. Raw data: `" << stem << "-runs.csv` (one line per run), `" << stem
     << "-rows.csv` (one line per table row).\n\n";
  std::size_t planned = 0;
  for (const auto& [row, count] : report.planned) planned += count;
  if (report.runs.size() < planned)
    md << "**In progress:** " << report.runs.size() << " of the " << planned
       << " runs are in so far (a report from the journal, `--report-only`). Rows marked ‡ are partial: not all "
          "their pairs and trials have run, so their figures and the targets below are provisional.\n\n";
  summary_section(md, report);
  configuration_section(md, report);
  targets_section(md, report, rows);
  md << "How the runs are made:\n\n"
     << "- Every run (one method, one pair, one trial) is a fresh process: its peak RSS (getrusage of that "
        "child) is that method's alone, including its copy of the two clouds; a run still going "
     << kHardLimitSlack_s
     << " s after the wall cap is killed and counted as failed, and each process has an address-space cap "
        "(--memory-cap-mb, 12 GB by default; the machine is shared) past which the run fails as out of memory. "
        "Runs are interleaved (trial 1: k4reg K-4PCS, PCL K-4PCS, PCL FPFH + SAC-IA, Open3D FPFH + RANSAC, "
        "Open3D FPFH + FGR, k4reg 4PCS, PCL 4PCS; trial 2: …), each method selected by --methods (default: all whose "
        "library is installed).\n"
     << "- The machine is shared, so every run is timed on a quiet machine: a run during which other processes "
        "used more than a quarter of a core on average (/proc/stat minus the run's own CPU time) is repeated once "
        "the machine is quiet again (at most 3 attempts; the runs CSV has attempts and foreign_cores).\n"
     << "- T is the time from the two loaded clouds to the transform (file reading is the separate \"read\" "
        "column; copying into PCL clouds is not counted for PCL). k4reg uses both cores (TBB); PCL's "
        "KFPCS/FPCS use 2 OpenMP threads, its SIFTKeypoint is single-threaded.\n"
     << "- k4reg is seeded with the trial number (1, 2, …). PCL cannot be seeded (it calls srand(time())), so "
        "its trials differ by chance: the min–max of T and the SR over trials are its spread.\n"
     << "- PCL K-4PCS = `SIFTKeypoint<PointXYZI, PointWithScale>` (setScales(σ, 5, 5), setMinimumContrast(0.01 × "
        "the intensity range)) on each full cloud, then `KFPCSInitialAlignment` with setDelta(σ, false), "
        "setApproxOverlap(o), setScoreThreshold(0), setMaximumIterations(L), setMaxComputationTime(wall cap), "
        "setNumberOfThreads(2), where L is PCL's own iteration count for the overlap (45 at 0.8, 100 at 0.7, "
        "1849 at 0.4), capped as the configuration says. Clouds without intensity get PCL's geometric stand-in: "
        "NormalEstimationOMP curvature (radius 3σ) on a σ VoxelGrid, as the SIFT field. SIFT is deterministic, so "
        "it runs once per scan and σ (in its own process, timed there, its keypoints kept in the scan cache) and "
        "every trial starts KFPCS from those keypoints: PCL's T = SIFT time of both scans + that trial's KFPCS "
        "time, its peak RSS the larger of the two processes'. A SIFT killed at the hard limit is not run again on "
        "that scan. A run over the wall cap is a failure (†).\n"
     << "- PCL 4PCS = `VoxelGrid` at the spacing where our voxelised source has about as many points as our "
        "keypoints (the paper's baseline), then `FPCSInitialAlignment` with δ = that spacing (absolute) and the "
        "same settings. k4reg 4PCS = `register_clouds` with method = kPlain4pcs on the same spacing.\n"
     << "- The feature-based peers (issue 49) all describe a VoxelGrid at σ (V = σ) with FPFH, normals within 2 V, "
        "features within 5 V, 2 threads, and get no ICP (coarse = final). PCL FPFH + SAC-IA = `VoxelGrid`, "
        "`NormalEstimationOMP`, `FPFHEstimationOMP` (points without a finite normal or descriptor dropped), then "
        "`SampleConsensusInitialAlignment` as PCL's template-alignment tutorial sets it: 500 iterations (it has "
        "no time limit: a run past the cap is a failure like any other), samples ≥ 10 V apart, matches within 2 V "
        "(setMaxCorrespondenceDistance((2 V)²): its truncated error compares squared distances), seeded with the "
        "trial (srand). Open3D = "
        "`bench/open3d_pair.py` with Open3D 0.16 (Debian's python3-open3d) as its global-registration tutorial sets "
        "it: `voxel_down_sample(V)`, normals `KDTreeSearchParamHybrid(2 V, 30)`, FPFH `KDTreeSearchParamHybrid(5 V, "
        "100)`; RANSAC = `registration_ransac_based_on_feature_matching` (mutual filter, distance 1.5 V, "
        "point-to-point, 3 points, edge-length 0.9 and distance 1.5 V checkers, `RANSACConvergenceCriteria(100000, "
        "0.999)`), FGR = `registration_fgr_based_on_feature_matching` (maximum correspondence distance 0.5 V); "
        "`o3d.utility.random.seed(trial)`, OMP_NUM_THREADS = 2. It runs as a child of the worker: the worker writes "
        "the clouds' local-frame points (what PCL gets) to float PLY files; Open3D's T is what the script measures "
        "from both clouds in memory to the transform, and the rest of the call (writing the files, Python's start-up "
        "and `import open3d`, about 0.6 s, reading the files) is the runs CSV's convert_s, as copying into PCL clouds "
        "is for PCL. Peak RSS includes the Python child.\n"
     << "- Coarse = before the final ICP: for k4reg the best hypothesis after its symmetry guard, i.e. what "
        "icp = false returns. The guard settles every hypothesis with a short ICP before ranking, so k4reg's "
        "coarse RMSE is already ICP-grade and not the raw 4PCS-stage error the paper reports (register_clouds "
        "does not expose that). SR in Tables 2–4 is the coarse success, as in the paper. Real-data sources are moved "
        "by a fixed random rigid motion (30–180°) first, so that a method returning the identity cannot pass on "
        "pairs whose true motion is small.\n\n";
  table2(md, report, rows);
  comparison_table(md, report, rows, "Table 3 – indoor lab (simulated), S = 0.7M: 4PCS vs K-4PCS", "lab", 700000,
                   kPaperTable3);
  comparison_table(md, report, rows, "Table 4 – outdoor arch (simulated), S = 1.5M: 4PCS vs K-4PCS", "arch", 1500000,
                   kPaperTable4);
  real_table(md, report, rows);
  every_row_table(md, report, rows);
  keypoint_table(md, report);
  failures_section(md, report);
  if (suite_index(report, "lab") < report.suites.size())
    md << "![success rate vs sigma](" << stem << "-sr-vs-sigma.png)\n![time vs size](" << stem
       << "-time-vs-size.png)\n\n";
  md << "Paper values (in parentheses and in the \"paper\" columns) are from real Z+F scans of a real lab and "
        "arch (Theiler et al. 2014, Tables 2–4); our scenes are simulated look-alikes, so compare trends, not "
        "digits.\n";
  return md.str();
}

}  // namespace k4reg::bench
