// k4reg-bench-blind: pairwise registration on scenes and scans split into a tuning part and a held-out part.
// Thresholds are tuned on the tuning part only; the held-out part is run to report, and both go into
// bench/RESULTS.md (block "blind"), so a figure that holds only where it was tuned shows as such.
//
//   k4reg-bench-blind [--part tuning|held-out|all] [--suites NAME,...] [--seeds N] [--data-dir DIR]
//                     [--cache-dir DIR] [--results-dir DIR] [--markdown FILE] [--list] [--frame scanner|arbitrary]
//                     [--free-space auto|off]
//
// Every run is scored against the ground truth (RMSE over true correspondences, the paper's measure) and
// counted as a success, a flagged miss (the result said `ambiguous`) or a confident miss (wrong, unflagged:
// the one outcome a registration service must not give). Real sources are moved by a random rigid motion
// first (seeded), as a user's scans in arbitrary scanner frames would be.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <Eigen/Geometry>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "k4reg/io/cloud_io.h"
#include "k4reg/util/error.h"
#include "k4reg/io/gt_pairs.h"
#include "k4reg/registration/registration.h"
#include "markdown_block.h"
#include "random_motion.h"
#include "simulated_scan_cache.h"
#include "split_options.h"
#include "statistics.h"
#include "truth_error.h"

namespace fs = std::filesystem;

namespace k4reg::bench {
namespace {

using Clock = std::chrono::steady_clock;

struct Pair {
  PointCloud source, target;
  Eigen::Matrix4d truth;  // source -> target
};

// One suite: a set of pairs registered with one parameter set, judged with one threshold.
struct Suite {
  std::string name, part, what;  // part: "tuning" or "held-out"
  double min_scale_m = 0.0, overlap = 0.0;  // 0 = automatic
  double success_rmse_m = 0.5;
  std::vector<std::string> pairs;           // labels
  std::function<Pair(std::size_t pair, std::uint64_t seed)> load;
};

struct Run {
  std::string suite, part, pair;
  std::uint64_t seed = 0;
  bool success = false, ambiguous = false, failed = false;  // failed: an error instead of a result
  double rmse_m = kNan, seconds = 0.0, min_scale_used = 0.0, overlap_used = 0.0, margin = 0.0;
  std::string note;
};

// Pairs of a real data set (gt_pairs.log), chosen by index; each source moved by its own random motion.
Suite real_suite(std::string name, std::string part, std::string what, const fs::path& folder,
                 std::vector<std::size_t> chosen, double threshold, double min_scale_m, double overlap, double reach) {
  Suite s{std::move(name), std::move(part), std::move(what), min_scale_m, overlap, threshold, {}, {}};
  const auto all = std::make_shared<std::vector<GtPair>>(read_gt_pairs((folder / "gt_pairs.log").string()));
  auto path = [folder](const std::string& file) {
    const fs::path derived = folder / "derived" / fs::path(file).replace_extension(".ply");
    return fs::exists(derived) ? derived : folder / file;
  };
  std::vector<GtPair> pairs;
  for (std::size_t k : chosen) {
    pairs.push_back(all->at(k));
    s.pairs.push_back(all->at(k).source + "->" + all->at(k).target);
  }
  s.load = [pairs, path, reach](std::size_t k, std::uint64_t seed) {
    const GtPair& g = pairs.at(k);
    const Eigen::Matrix4d motion = random_motion(seed * 1000 + k, reach);
    return Pair{moved(read_cloud(path(g.source).string()), motion), read_cloud(path(g.target).string()),
                g.T_target_source * motion.inverse()};
  };
  return s;
}

// Station pairs of one layout of a simulated scene, with the success threshold, the fixed sigma of its "-sigma"
// and "-given" suites, and the overlap its "-given" suite states: the scene's nominal overlap as the issue's
// commands give it (`--overlap O`: about 0.5 in rooms and corridors, 0.4 outdoors), not measured per pair.
struct SceneSet {
  std::string scene;
  int layout = 0;
  std::vector<std::pair<int, int>> stations;
  std::size_t points = 700000;
  double success_rmse_m = 0.1;
  double fixed_sigma_m = 0.1;
  double given_overlap = 0.5;
};

// How a suite sets the parameters: both automatic, sigma given, or both given (the command).
enum class Given { kNothing, kSigma, kSigmaAndOverlap };

// The scans are cached on disk; the simulator gives every scan its own frame.
Suite simulated_suite(const SceneSet& set, std::string part, Given given, const std::string& cache_dir,
                      sim::ScanFrame frame) {
  const std::string label = set.scene + (set.layout > 0 ? "-L" + std::to_string(set.layout) : "") +
                            (frame == sim::ScanFrame::kArbitrary ? "-arb" : "");
  const char* suffix[] = {"-auto", "-sigma", "-given"};
  const std::string name = label + suffix[static_cast<int>(given)];
  const std::string what =
      set.scene + " layout " + std::to_string(set.layout) +
      (given == Given::kNothing  ? std::string(", automatic sigma and overlap")
       : given == Given::kSigma ? fmt::format(", sigma {} m, automatic overlap", set.fixed_sigma_m)
                                : fmt::format(", sigma {} m, overlap {}", set.fixed_sigma_m, set.given_overlap));
  Suite s{name,
          std::move(part),
          what,
          given == Given::kNothing ? 0.0 : set.fixed_sigma_m,
          given == Given::kSigmaAndOverlap ? set.given_overlap : 0.0,
          set.success_rmse_m,
          {},
          {}};
  for (auto [a, b] : set.stations) s.pairs.push_back(label + " " + std::to_string(a) + "->" + std::to_string(b));
  s.load = [=](std::size_t k, std::uint64_t) {
    const CachedScan a =
        cached_simulated_scan(cache_dir, set.scene, set.stations.at(k).first, set.points, set.layout, frame);
    const CachedScan b =
        cached_simulated_scan(cache_dir, set.scene, set.stations.at(k).second, set.points, set.layout, frame);
    return Pair{read_cloud(a.path), read_cloud(b.path), source_to_target_truth(a, b)};
  };
  return s;
}

// frame: the simulated scans' (real sources are always moved by a random motion).
std::vector<Suite> all_suites(const fs::path& data, const std::string& cache, sim::ScanFrame frame) {
  const fs::path bunny = data / "stanford-bunny-scans", kurt = data / "3dtk-kurt3d-scans";
  std::vector<Suite> suites;
  // Real objects: the bunny's pairs alternate between the parts (even log lines tune, odd ones are held out).
  std::vector<std::size_t> even, odd;
  for (std::size_t k = 0; k < read_gt_pairs((bunny / "gt_pairs.log").string()).size(); ++k) (k % 2 ? odd : even).push_back(k);
  for (const auto& [part, pairs] : {std::pair{"tuning", even}, std::pair{"held-out", odd}}) {
    suites.push_back(real_suite(std::string("bunny-3mm-") + part, part, "Stanford bunny, sigma 3 mm, overlap 0.6",
                                bunny, pairs, 0.005, 0.003, 0.6, 0.2));
    suites.push_back(real_suite(std::string("bunny-auto-") + part, part, "Stanford bunny, automatic sigma and overlap",
                                bunny, pairs, 0.005, 0.0, 0.0, 0.2));
  }
  // Real indoor scans in centimetres, never tuned on.
  suites.push_back(real_suite("kurt3d-cm-auto", "held-out", "3DTK Kurt3D indoor scans as given (cm), automatic", kurt,
                              {0}, 25.0, 0.0, 0.0, 500.0));
  // Simulated. Tuning: the lab, the canonical layout (0) of the hall, the corridor and the object, and
  // layouts 3-4 of the monument (added when its layouts 0-1 had shown confident misses: the fix was made
  // on 3-4 only). Held out: whole scenes never tuned on (courtyard, arch), layouts 0-1 of the monument,
  // and other layouts of the tuning scenes (their dimensions, details and stations drawn afresh).
  const std::vector<std::pair<int, int>> hall_pairs{{0, 1}, {2, 3}}, corridor_pairs{{0, 1}, {1, 2}},
      object_pairs{{0, 1}, {3, 4}, {7, 8}}, monument_pairs{{0, 1}, {0, 3}, {3, 2}},
      courtyard_pairs{{0, 1}, {1, 2}, {2, 3}, {3, 0}};
  const std::vector<std::pair<SceneSet, std::string>> sets{
      {{"lab", 0, {{0, 1}, {2, 3}, {1, 4}}, 700000, 0.1, 0.1, 0.8}, "tuning"},
      {{"hall", 0, {{0, 1}, {2, 3}, {0, 4}}}, "tuning"},
      {{"corridor", 0, corridor_pairs}, "tuning"},
      {{"object", 0, {{0, 1}, {2, 3}, {5, 6}}, 40000, 0.005, 0.002, 0.6}, "tuning"},
      {{"monument", 3, monument_pairs, 1500000, 0.1, 0.1, 0.4}, "tuning"},
      {{"monument", 4, monument_pairs, 1500000, 0.1, 0.1, 0.4}, "tuning"},
      {{"hall", 1, hall_pairs}, "held-out"},
      {{"hall", 2, hall_pairs}, "held-out"},
      {{"corridor", 1, corridor_pairs}, "held-out"},
      {{"corridor", 2, corridor_pairs}, "held-out"},
      {{"object", 1, object_pairs, 40000, 0.005, 0.002, 0.6}, "held-out"},
      {{"object", 2, object_pairs, 40000, 0.005, 0.002, 0.6}, "held-out"},
      {{"monument", 0, monument_pairs, 1500000, 0.1, 0.1, 0.4}, "held-out"},
      {{"monument", 1, monument_pairs, 1500000, 0.1, 0.1, 0.4}, "held-out"},
      {{"courtyard", 0, courtyard_pairs, 700000, 0.1, 0.1, 0.4}, "held-out"},
      {{"courtyard", 1, courtyard_pairs, 700000, 0.1, 0.1, 0.4}, "held-out"},
      {{"arch", 0, {{0, 1}, {2, 3}}, 1500000, 0.1, 0.1, 0.4}, "held-out"},
  };
  for (const auto& [set, part] : sets)
    for (Given given : {Given::kNothing, Given::kSigma, Given::kSigmaAndOverlap})
      suites.push_back(simulated_suite(set, part, given, cache, frame));
  return suites;
}

Run run_one(const Suite& suite, std::size_t k, std::uint64_t seed, FreeSpaceCheck free_space) {
  Run run;
  run.suite = suite.name, run.part = suite.part, run.pair = suite.pairs[k], run.seed = seed;
  const Pair pair = suite.load(k, seed);
  RegistrationParams params;
  params.min_scale_m = suite.min_scale_m;
  params.overlap = suite.overlap;
  params.seed = seed;
  params.free_space = free_space;
  const auto start = Clock::now();
  try {
    const RegistrationResult r = register_clouds(pair.source, pair.target, params);
    run.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    run.rmse_m = file_frame_error(pair.source, r.transform, pair.truth).rmse_m;
    run.success = run.rmse_m < suite.success_rmse_m;
    run.ambiguous = r.ambiguous;
    run.min_scale_used = r.min_scale_m_used;
    run.overlap_used = r.overlap_used;
    run.margin = r.ambiguity_margin;
    run.note = r.ambiguity_reason;
    for (std::size_t h = 0; h < std::min<std::size_t>(3, r.hypotheses.size()); ++h) {
      char scores[128];
      std::snprintf(scores, sizeof scores, " [#%zu cloud %.2f refined %.2f surface %.2f err %.3g]", h + 1,
                    r.hypotheses[h].cloud_score, r.hypotheses[h].refined_score, r.hypotheses[h].surface_agreement,
                    file_frame_error(pair.source, r.hypotheses[h].transform, pair.truth).rmse_m);
      run.note += scores;
    }
  } catch (const Error& e) {
    run.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    run.failed = true;  // a clear refusal: not a confident miss
    run.note = e.what();
  }
  return run;
}

std::string report(const std::vector<Suite>& suites, const std::vector<Run>& runs) {
  std::ostringstream out;
  out << "| part | suite | what | runs | success | flagged miss | refused | **confident miss** | median time |\n"
         "|---|---|---|---:|---:|---:|---:|---:|---:|\n";
  for (const std::string part : {"tuning", "held-out"})
    for (const Suite& s : suites) {
      if (s.part != part) continue;
      int n = 0, ok = 0, flagged = 0, refused = 0, confident = 0;
      std::vector<double> times;
      for (const Run& r : runs) {
        if (r.suite != s.name) continue;
        ++n;
        times.push_back(r.seconds);
        if (r.failed) ++refused;
        else if (r.success) ++ok;
        else if (r.ambiguous) ++flagged;
        else ++confident;
      }
      if (n == 0) continue;
      char line[512];
      std::snprintf(line, sizeof line, "| %s | %s | %s | %d | %d (%.0f %%) | %d | %d | **%d** | %.2f s |\n", part.c_str(),
                    s.name.c_str(), s.what.c_str(), n, ok, 100.0 * ok / n, flagged, refused, confident, median(times));
      out << line;
    }
  return out.str();
}

}  // namespace
}  // namespace k4reg::bench

int main(int argc, char** argv) {
  using namespace k4reg::bench;
  CLI::App app{"Registers the blind protocol's tuning and held-out pairs and reports both."};
  SplitOptions o;
  o.seeds = 3;
  o.add_to(app, "blind");
  std::string frame = "scanner";
  app.add_option("--frame", frame,
                 "the simulated scans' frames: scanner (scanner at the origin) or arbitrary (also shifted up to 30 m per "
                 "axis; suites named -arb, results in blind-arbitrary-runs.csv and the RESULTS block blind-arbitrary)")
      ->check(CLI::IsMember({"scanner", "arbitrary"}));
  std::string free_space = "auto";
  app.add_option("--free-space", free_space,
                 "auto (as a user gets it) or off (geometry alone: results in blind[-arbitrary]-geometry-runs.csv and "
                 "the RESULTS block blind[-arbitrary]-geometry)")
      ->check(CLI::IsMember({"auto", "off"}));
  CLI11_PARSE(app, argc, argv);
  const bool arbitrary = frame == "arbitrary";
  const bool geometry_only = free_space == "off";
  const std::string stem = std::string(arbitrary ? "blind-arbitrary" : "blind") + (geometry_only ? "-geometry" : "");
  try {
    const auto suites =
        all_suites(o.data_dir, o.cache_dir, arbitrary ? k4reg::sim::ScanFrame::kArbitrary : k4reg::sim::ScanFrame::kScanner);
    if (o.list) {  // before the CSV is opened: listing must not empty the last run's results
      for (const Suite& s : suites)
        std::printf("%-22s %-9s %zu pairs  %s\n", s.name.c_str(), s.part.c_str(), s.pairs.size(), s.what.c_str());
      return 0;
    }
    std::vector<Run> runs;
    fs::create_directories(o.results_dir);
    std::ofstream csv(fs::path(o.results_dir) / (stem + "-runs.csv"));
    csv << "part,suite,pair,seed,success,ambiguous,refused,rmse_m,seconds,min_scale_m_used,overlap_used,margin,note\n";
    for (const Suite& s : suites) {
      if (!o.selected(s.part, s.name)) continue;
      for (std::size_t k = 0; k < s.pairs.size(); ++k)
        for (int seed = 1; seed <= o.seeds; ++seed) {
          const Run r = run_one(s, k, seed, geometry_only ? k4reg::FreeSpaceCheck::kOff : k4reg::FreeSpaceCheck::kAuto);
          runs.push_back(r);
          std::printf("%-9s %-20s %-28s seed %d: %s rmse %.4g (%.2f s, sigma %.3g, overlap %.2f, margin %.3f) %s\n",
                      r.part.c_str(), r.suite.c_str(), r.pair.c_str(), seed,
                      r.failed ? "REFUSED" : r.success ? "ok  " : r.ambiguous ? "FLAG" : "MISS", r.rmse_m, r.seconds,
                      r.min_scale_used, r.overlap_used, r.margin, r.note.c_str());
          std::fflush(stdout);
          csv << r.part << ',' << r.suite << ',' << r.pair << ',' << seed << ',' << r.success << ',' << r.ambiguous << ','
              << r.failed << ',' << r.rmse_m << ',' << r.seconds << ',' << r.min_scale_used << ',' << r.overlap_used << ','
              << r.margin << ",\"" << r.note << "\"\n";
        }
    }
    const std::string table = report(suites, runs);
    std::printf("\n%s", table.c_str());
    if (!o.markdown.empty()) replace_block(o.markdown, stem, table);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "k4reg-bench-blind: %s\n", e.what());
    return 1;
  }
  return 0;
}
