// k4reg-bench-project: project registration (register_project, as `k4reg align-project` runs it) on
// simulated and real projects, split into a tuning part and a held-out part like k4reg-bench-blind.
//
//   k4reg-bench-project [--part tuning|held-out|all|scaling] [--suites NAME,...] [--seeds N] [--data-dir DIR]
//                       [--cache-dir DIR] [--results-dir DIR] [--markdown FILE] [--list]
//                       [--frames scanner|arbitrary|mixed] [--free-space auto|off]
//
// The scaling part (not in "all": about 15 minutes) registers the courtyard's first 6, 12 and 24 stations at 1 M
// points, all pairs, automatic overlap (and 12 with the overlap given as 0.4), then the 24 stations, the bunny and
// two statuettes with screened pairs, and splits the time into reading, the screen, the per-scan stages, the pairs,
// selection and refinement.
// It writes its own CSV (project-scaling-runs.csv) and RESULTS.md block ("project-scaling").
//
// Every scan's pose is scored against the ground truth relative to the reference scan (RMS over the
// scan's points of the distance between where the pose and the truth put them) and counted as correct,
// not registered (a refusal), or a confident miss (registered but off: the outcome to avoid).
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>

#include "k4reg/io/cloud_io.h"
#include "k4reg/io/gt_pairs.h"
#include "k4reg/project/project_registration.h"
#include "k4reg/util/error.h"
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

struct Project {
  double read_seconds = 0.0;  // reading the scan files (not simulating them)
  std::vector<PointCloud> scans;
  std::vector<Eigen::Matrix4d> truth;  // scan -> a common frame
};

struct Suite {
  std::string name, part, what;
  double min_scale_m = 0.0, overlap = 0.0;  // 0 = automatic
  double success_rmse_m = 0.05;
  std::function<Project(std::uint64_t seed)> load;
  PairSelection pairs = PairSelection::kAll;
};

struct Run {
  std::string suite, part;
  std::uint64_t seed = 0;
  std::size_t scans = 0, correct = 0, unregistered = 0, confident_misses = 0, links = 0, accepted = 0;
  std::size_t loops = 0, inconsistent = 0;
  // Of the unregistered scans, those held too weakly whose two candidate placements came with them, and how many
  // of those the preferred (first) placement put right.
  std::size_t ambiguous = 0, ambiguous_preferred_right = 0;
  double worst_rmse_m = 0.0, seconds = 0.0;
  double read_seconds = 0.0;
  std::vector<StageTiming> timings;  // the project's: pairwise stages summed over pairs, selection, refinement
  bool refused = false;
  std::string note;
};

// Where the simulated scans come from, and in which frames: every scan in its scanner's, every scan in an arbitrary
// one (shifted up to 30 m), or the odd-numbered stations of each project in arbitrary ones (mixed).
enum class Frames { kScanner, kArbitrary, kMixed };
struct SimulatedSource {
  std::string cache_dir;
  Frames frames = Frames::kScanner;
  const char* suffix() const { return frames == Frames::kArbitrary ? "-arb" : frames == Frames::kMixed ? "-mix" : ""; }
  sim::ScanFrame frame_of(std::size_t k) const {
    const bool arbitrary = frames == Frames::kArbitrary || (frames == Frames::kMixed && k % 2 == 1);
    return arbitrary ? sim::ScanFrame::kArbitrary : sim::ScanFrame::kScanner;
  }
};

// tag: told into the name where one layout is registered with two sets of stations.
Suite simulated(const std::string& scene, int layout, std::vector<int> stations, std::size_t points, double threshold,
                double min_scale_m, double overlap, std::string part, const SimulatedSource& cache,
                const std::string& tag = {}) {
  Suite s{fmt::format("{}-L{}-{}st{}{}", scene, layout, stations.size(), tag, cache.suffix()), std::move(part),
          fmt::format("{} layout {}, stations {}, {} k points, sigma {}, overlap {}", scene, layout,
                      fmt::join(stations, " "), points / 1000, min_scale_m > 0 ? fmt::format("{} m", min_scale_m) : "auto",
                      overlap > 0 ? fmt::format("{}", overlap) : "auto"),
          min_scale_m, overlap, threshold, {}};
  s.load = [=](std::uint64_t) {
    Project p;
    for (std::size_t k = 0; k < stations.size(); ++k) {
      const CachedScan c = cached_simulated_scan(cache.cache_dir, scene, stations[k], points, layout, cache.frame_of(k));
      const auto start = Clock::now();
      p.scans.push_back(read_cloud(c.path));
      p.read_seconds += std::chrono::duration<double>(Clock::now() - start).count();
      p.truth.push_back(c.scan_to_scene);
    }
    return p;
  };
  return s;
}

// Scans of a real data set whose gt_pairs.log links them all to `files[0]`, each moved at random.
Suite real(std::string name, std::string what, const fs::path& folder, std::vector<std::string> files, double threshold,
           double min_scale_m, double overlap, std::string part) {
  Suite s{std::move(name), std::move(part), std::move(what), min_scale_m, overlap, threshold, {}};
  s.load = [=](std::uint64_t seed) {
    // Poses into files[0]'s frame, chained through the log's pairs.
    std::map<std::string, Eigen::Matrix4d> to_first{{files[0], Eigen::Matrix4d::Identity()}};
    const std::vector<GtPair> pairs = read_gt_pairs((folder / "gt_pairs.log").string());
    for (bool grew = true; grew;) {
      grew = false;
      for (const GtPair& g : pairs) {
        if (to_first.count(g.target) && !to_first.count(g.source))
          to_first[g.source] = to_first[g.target] * g.T_target_source, grew = true;
        else if (to_first.count(g.source) && !to_first.count(g.target))
          to_first[g.target] = to_first[g.source] * g.T_target_source.inverse(), grew = true;
      }
    }
    Project p;
    for (std::size_t i = 0; i < files.size(); ++i) {
      const Eigen::Matrix4d motion = random_motion(seed * 1000 + i, 0.2);
      p.scans.push_back(moved(read_cloud((folder / files[i]).string()), motion));
      p.truth.push_back(to_first.at(files[i]) * motion.inverse());
    }
    return p;
  };
  return s;
}

// The same project with each scan's best partners only (partner_screen.h), in the scaling part.
Suite screened(Suite s) {
  s.name += "-screened";
  s.what += ", screened pairs (4 partners per scan)";
  s.part = "scaling";
  s.pairs = PairSelection::kScreened;
  return s;
}

std::vector<int> stations_up_to(int n) {
  std::vector<int> stations(n);
  for (int i = 0; i < n; ++i) stations[i] = i;
  return stations;
}

std::vector<Suite> all_suites(const fs::path& data, const SimulatedSource& cache) {
  const auto bunny_10 = [&](const std::string& part) {
    return real("bunny-10", "Stanford bunny, all 10 scans, sigma 2 mm, overlap 0.5", data / "stanford-bunny-scans",
                {"bun000.ply", "bun045.ply", "bun090.ply", "bun180.ply", "bun270.ply", "bun315.ply", "chin.ply",
                 "ear_back.ply", "top2.ply", "top3.ply"},
                0.001, 0.002, 0.5, part);
  };
  // Tuning: what the selection was developed on (the bunny's ten scans, hall layout 0, monument layout 3).
  // Held out: other layouts of those scenes, the simulated statuette, the courtyard. The scan strength
  // rule (scan_strength.h) came after a first run of the held-out part had refused hall layouts 1-2, so
  // those two are reported as seen; hall layout 3 and object layout 2 were added unseen after it.
  return {
      bunny_10("tuning"),
      simulated("hall", 0, {0, 1, 2, 4}, 700000, 0.05, 0.1, 0.4, "tuning", cache),
      simulated("monument", 3, {0, 1, 2}, 700000, 0.1, 0.1, 0.4, "tuning", cache),
      simulated("hall", 1, {0, 1, 2, 4}, 700000, 0.05, 0.1, 0.4, "held-out", cache),
      simulated("hall", 2, {0, 1, 3, 4}, 700000, 0.05, 0.1, 0.4, "held-out", cache),
      simulated("monument", 0, {0, 1, 2}, 700000, 0.1, 0.1, 0.4, "held-out", cache),
      simulated("monument", 1, {0, 1, 3}, 700000, 0.1, 0.1, 0.4, "held-out", cache),
      simulated("monument", 2, {0, 1, 2}, 700000, 0.1, 0.1, 0.4, "held-out", cache),
      // Object layout 1 became tuning when the object views' free space was developed on it (2026-12-06).
      simulated("object", 1, {0, 1, 2, 3, 4, 5, 6, 7, 8, 9}, 40000, 0.001, 0.002, 0.5, "tuning", cache),
      simulated("courtyard", 0, {0, 1, 2, 3}, 700000, 0.1, 0.1, 0.4, "held-out", cache),
      // Hall layout 3 became tuning when one twin motion per cut was developed on it (2026-12-06, twelfth session).
      simulated("hall", 3, {0, 1, 2, 4}, 700000, 0.05, 0.1, 0.4, "tuning", cache),
      simulated("object", 2, {0, 1, 2, 3, 4, 5, 6, 7, 8, 9}, 40000, 0.001, 0.002, 0.5, "held-out", cache),
      // Added unseen with the loop-implied poses (issue 21): reported as first run.
      simulated("monument", 4, {0, 1, 2}, 700000, 0.1, 0.1, 0.4, "held-out", cache),
      simulated("hall", 4, {0, 1, 2, 4}, 700000, 0.05, 0.1, 0.4, "held-out", cache),
      simulated("courtyard", 1, {0, 1, 2, 3}, 700000, 0.1, 0.1, 0.4, "held-out", cache),
      // The monument as the check has it: front, back, and front-side stations (two of the three pairs
      // from opposite sides). Layouts 0 and 2-7 were looked at while the geometric signal's turn, the judging
      // scale and the tied loop poses were developed (2026-12-05): tuning. Layouts 8-10 added unseen after.
      simulated("monument", 0, {0, 1, 3}, 700000, 0.1, 0.1, 0.4, "tuning", cache, "-fbs"),
      simulated("monument", 2, {0, 1, 3}, 700000, 0.1, 0.1, 0.4, "tuning", cache, "-fbs"),
      simulated("monument", 3, {0, 1, 3}, 700000, 0.1, 0.1, 0.4, "tuning", cache, "-fbs"),
      simulated("monument", 4, {0, 1, 3}, 700000, 0.1, 0.1, 0.4, "tuning", cache, "-fbs"),
      simulated("monument", 5, {0, 1, 3}, 700000, 0.1, 0.1, 0.4, "tuning", cache, "-fbs"),
      simulated("monument", 6, {0, 1, 3}, 700000, 0.1, 0.1, 0.4, "tuning", cache, "-fbs"),
      simulated("monument", 7, {0, 1, 3}, 700000, 0.1, 0.1, 0.4, "tuning", cache, "-fbs"),
      simulated("monument", 8, {0, 1, 3}, 700000, 0.1, 0.1, 0.4, "held-out", cache, "-fbs"),
      simulated("monument", 9, {0, 1, 3}, 700000, 0.1, 0.1, 0.4, "held-out", cache, "-fbs"),
      simulated("monument", 10, {0, 1, 3}, 700000, 0.1, 0.1, 0.4, "held-out", cache, "-fbs"),
      // Added unseen after the links judged from both sides (2026-12-05), which hall layouts 1 and 4 (held out
      // until then, refused three of four stations) were looked at for: their first run is reported.
      simulated("hall", 5, {0, 1, 2, 4}, 700000, 0.05, 0.1, 0.4, "held-out", cache),
      simulated("hall", 6, {0, 1, 2, 4}, 700000, 0.05, 0.1, 0.4, "held-out", cache),
      simulated("hall", 7, {0, 1, 2, 4}, 700000, 0.05, 0.1, 0.4, "held-out", cache),
      // Added unseen after the object views' free space (2026-12-06; developed on object layout 1 and the bunny):
      // their first run is reported.
      simulated("object", 3, stations_up_to(10), 40000, 0.001, 0.002, 0.5, "held-out", cache),
      simulated("object", 4, stations_up_to(10), 40000, 0.001, 0.002, 0.5, "held-out", cache),
      simulated("object", 5, stations_up_to(10), 40000, 0.001, 0.002, 0.5, "held-out", cache),
      // Added unseen after the conflict rule counted a scan's accepted links against the confident ones that
      // contradict it (2026-12-06; made on object layout 4, whose first run is the row above).
      simulated("object", 6, stations_up_to(10), 40000, 0.001, 0.002, 0.5, "held-out", cache),
      simulated("object", 7, stations_up_to(10), 40000, 0.001, 0.002, 0.5, "held-out", cache),
      // Added unseen after the pose graph's second, tighter kernel (2026-12-06; made on object layouts 3 and 4).
      simulated("object", 8, stations_up_to(10), 40000, 0.001, 0.002, 0.5, "held-out", cache),
      simulated("object", 9, stations_up_to(10), 40000, 0.001, 0.002, 0.5, "held-out", cache),
      // The lab as a 4-station project (opposite corners and two heights), added unseen with the scanner positions
      // estimated from the scans (issue 46): its first run is reported.
      simulated("lab", 0, {0, 1, 2, 3}, 700000, 0.05, 0.1, 0.5, "held-out", cache),
      // The statuette from 15 views every 24 deg, as the real statue set (its own layouts: object15's
      // dice differ from object's). Added unseen after the pairs searched from the other side (2026-12-06;
      // made on object layout 5): their first run is reported.
      simulated("object15", 0, stations_up_to(15), 40000, 0.001, 0.002, 0.5, "held-out", cache),
      simulated("object15", 1, stations_up_to(15), 40000, 0.001, 0.002, 0.5, "held-out", cache),
      simulated("object15", 2, stations_up_to(15), 40000, 0.001, 0.002, 0.5, "held-out", cache),
      simulated("object15", 3, stations_up_to(15), 40000, 0.001, 0.002, 0.5, "held-out", cache),
      // The corridor (doors every 4 m, half-turn symmetric, few details that break either symmetry) as projects.
      // Added after a two-scan project of layout 1 registered the truth's half turn, 180 deg off, on a reverse
      // margin of 1 that a runner-up the target's side had not refined gave it (2026-12-06): layouts 0 (the pairs'
      // tuning layout) and 1 are seen; layouts 2-4 were added unseen after the fix, their first run is reported.
      simulated("corridor", 1, {0, 1}, 700000, 0.05, 0.1, 0.4, "tuning", cache),
      simulated("corridor", 0, {0, 1, 2}, 700000, 0.05, 0.1, 0.4, "tuning", cache),
      simulated("corridor", 1, {0, 1, 2}, 700000, 0.05, 0.1, 0.4, "tuning", cache),
      simulated("corridor", 2, {0, 1, 2}, 700000, 0.05, 0.1, 0.4, "held-out", cache),
      simulated("corridor", 3, {0, 1, 2}, 700000, 0.05, 0.1, 0.4, "held-out", cache),
      simulated("corridor", 4, {0, 1, 2}, 700000, 0.05, 0.1, 0.4, "held-out", cache),
      // The default, automatic overlap (bases for 0.8, 0.6, then 0.4 until a pose is well supported), and the
      // 12 stations again with the overlap given as 0.4 (the full bases for 0.4 on every pair).
      simulated("courtyard", 0, stations_up_to(6), 1000000, 0.1, 0.1, 0.0, "scaling", cache),
      simulated("courtyard", 0, stations_up_to(12), 1000000, 0.1, 0.1, 0.0, "scaling", cache),
      simulated("courtyard", 0, stations_up_to(24), 1000000, 0.1, 0.1, 0.0, "scaling", cache),
      simulated("courtyard", 0, stations_up_to(12), 1000000, 0.1, 0.1, 0.4, "scaling", cache, "-overlap0.4"),
      // The partner screen (added 2026-12-05): the 24 stations, and sets where pairs across the object do not
      // overlap.
      screened(simulated("courtyard", 0, stations_up_to(24), 1000000, 0.1, 0.1, 0.0, "scaling", cache)),
      screened(bunny_10("scaling")),
      screened(simulated("object", 1, stations_up_to(10), 40000, 0.001, 0.002, 0.5, "scaling", cache)),
      screened(simulated("object", 2, stations_up_to(10), 40000, 0.001, 0.002, 0.5, "scaling", cache)),
      // Held out from the screen's development (the four above shaped it: the surface score, the second round of
      // partners): run once, reported as they came.
      screened(simulated("courtyard", 3, stations_up_to(20), 700000, 0.1, 0.1, 0.0, "scaling", cache)),
      screened(simulated("object", 3, stations_up_to(10), 40000, 0.001, 0.002, 0.5, "scaling", cache)),
  };
}

Run run_one(const Suite& suite, std::uint64_t seed, FreeSpaceCheck free_space) {
  Run run;
  run.suite = suite.name, run.part = suite.part, run.seed = seed;
  const Project project = suite.load(seed);
  run.scans = project.scans.size();
  ProjectParams params;
  params.pairwise.min_scale_m = suite.min_scale_m;
  params.pairwise.overlap = suite.overlap;
  params.pairwise.seed = seed;
  params.pairwise.free_space = free_space;
  params.pairs = suite.pairs;
  const auto start = Clock::now();
  try {
    const ProjectResult r = register_project(project.scans, params);
    run.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    run.read_seconds = project.read_seconds;
    run.timings = r.timings;
    const Eigen::Matrix4d to_reference = project.truth[r.reference].inverse();
    for (std::size_t i = 0; i < r.scans.size(); ++i) {
      auto error_m = [&](const Eigen::Matrix4d& pose) {
        return file_frame_error(project.scans[i], pose, to_reference * project.truth[i]).rmse_m;
      };
      if (!r.scans[i].registered) {
        ++run.unregistered;
        run.note += fmt::format(" {}:unregistered", i);
        if (r.scans[i].ambiguous && !r.scans[i].candidate_poses.empty()) {
          ++run.ambiguous;
          std::vector<std::string> right;
          for (std::size_t k = 0; k < r.scans[i].candidate_poses.size(); ++k)
            if (error_m(r.scans[i].candidate_poses[k]) < suite.success_rmse_m) right.push_back(k == 0 ? "preferred" : "twin");
          run.ambiguous_preferred_right += !right.empty() && right.front() == "preferred";
          run.note += fmt::format(" (ambiguous: {} right)", right.empty() ? "neither" : fmt::format("{}", fmt::join(right, "+")));
        }
        continue;
      }
      const double rmse = error_m(r.scans[i].pose);
      run.worst_rmse_m = std::max(run.worst_rmse_m, rmse);
      if (rmse < suite.success_rmse_m) {
        ++run.correct;
      } else {
        ++run.confident_misses;
        run.note += fmt::format(" {}:off {:.3g} m", i, rmse);
      }
    }
    run.links = r.links.size();
    for (const ProjectLink& l : r.links) run.accepted += l.accepted;
    run.loops = r.loops_checked;
    run.inconsistent = r.loops_inconsistent;
  } catch (const Error& e) {
    run.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    run.refused = true;
    run.note = e.what();
  }
  return run;
}

std::string report(const std::vector<Suite>& suites, const std::vector<Run>& runs) {
  std::ostringstream out;
  out << "| part | project | what | runs | scans | correct | not registered | **confident miss** | worst error | "
         "links accepted | median time |\n|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const std::string part : {"tuning", "held-out"})
    for (const Suite& s : suites) {
      if (s.part != part) continue;
      std::size_t n = 0, scans = 0, correct = 0, unregistered = 0, confident = 0, links = 0, accepted = 0;
      std::size_t ambiguous = 0, preferred_right = 0;
      double worst = 0.0;
      std::vector<double> times;
      for (const Run& r : runs) {
        if (r.suite != s.name) continue;
        ++n, scans += r.scans, correct += r.correct, confident += r.confident_misses, links += r.links, accepted += r.accepted;
        unregistered += r.refused ? r.scans : r.unregistered;
        ambiguous += r.ambiguous, preferred_right += r.ambiguous_preferred_right;
        worst = std::max(worst, r.worst_rmse_m);
        times.push_back(r.seconds);
      }
      if (n == 0) continue;
      const std::string not_registered =
          ambiguous == 0 ? fmt::format("{}", unregistered)
                         : fmt::format("{} ({} ambiguous, preferred right {})", unregistered, ambiguous, preferred_right);
      out << fmt::format("| {} | {} | {} | {} | {} | {} ({:.0f} %) | {} | **{}** | {:.3g} m (limit {:g}) | {} / {} | {:.1f} s |\n",
                         part, s.name, s.what, n, scans, correct, 100.0 * correct / scans, not_registered, confident, worst,
                         s.success_rmse_m, accepted, links, median(times));
    }
  return out.str();
}

double stage_seconds(const Run& r, std::initializer_list<const char*> stages) {
  double sum = 0.0;
  for (const StageTiming& t : r.timings)
    for (const char* stage : stages) sum += t.stage == stage ? t.seconds : 0.0;
  return sum;
}

// Where a project's time goes as it grows: reading, the per-scan stages (each scan prepared once), the pairs,
// judging weak links from both sides, selection, judging the poses open loops imply, and refinement; all pairs, so the pairs grow as N(N-1)/2.
std::string scaling_report(const std::vector<Run>& runs) {
  std::ostringstream out;
  out << "| project | scans | pairs | correct | not registered | **confident miss** | wall | read | screen | per-scan stages | "
         "pairs | both sides | selection | loop poses | refinement |\n"
         "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const Run& r : runs) {
    if (r.part != "scaling") continue;
    const double per_scan = stage_seconds(r, {"voxel_grid", "scanner_position", "keypoints", "icp_setup"});
    const double pairs = stage_seconds(r, {"matching", "symmetry_guard", "icp", "verdict", "polish", "plain_grid"});
    out << fmt::format(
        "| {} | {} | {} | {} | {} | **{}** | {:.1f} s | {:.1f} s | {:.1f} s | {:.1f} s | {:.1f} s | {:.1f} s | {:.2f} s | {:.1f} s | "
        "{:.2f} s |\n",
        r.suite, r.scans, r.links, r.correct, r.refused ? r.scans : r.unregistered, r.confident_misses,
        r.read_seconds + r.seconds, r.read_seconds, stage_seconds(r, {"screen"}), per_scan, pairs, stage_seconds(r, {"both_sides"}),
        stage_seconds(r, {"selection"}), stage_seconds(r, {"loop_poses"}),
        stage_seconds(r, {"refinement"}));
  }
  return out.str();
}

}  // namespace
}  // namespace k4reg::bench

int main(int argc, char** argv) {
  using namespace k4reg::bench;
  CLI::App app{"Registers the tuning and held-out projects and reports both, scan by scan against the truth."};
  SplitOptions o;
  o.seeds = 1;
  o.add_to(app, "project", "scaling");
  std::string frames = "scanner";
  app.add_option("--frames", frames,
                 "the simulated scans' frames: scanner, arbitrary (shifted up to 30 m per axis) or mixed (odd stations "
                 "arbitrary); projects named -arb / -mix, results in project[-scaling]-FRAMES-runs.csv and the block "
                 "project[-scaling]-FRAMES")
      ->check(CLI::IsMember({"scanner", "arbitrary", "mixed"}));
  std::string free_space = "auto";
  app.add_option("--free-space", free_space,
                 "auto (as a user gets it) or off (geometry alone: results in project[-scaling]-FRAMES-geometry-runs.csv "
                 "and the block project[-scaling]-FRAMES-geometry)")
      ->check(CLI::IsMember({"auto", "off"}));
  CLI11_PARSE(app, argc, argv);
  try {
    const SimulatedSource source{o.cache_dir, frames == "arbitrary" ? Frames::kArbitrary
                                              : frames == "mixed"   ? Frames::kMixed
                                                                    : Frames::kScanner};
    const bool geometry_only = free_space == "off";
    const std::string named = (frames == "scanner" ? "" : "-" + frames) + (geometry_only ? "-geometry" : "");
    const auto suites = all_suites(o.data_dir, source);
    if (o.list) {  // before the CSV is opened: listing must not empty the last run's results
      for (const Suite& s : suites)
        std::printf("%-22s %-9s %s\n", s.name.c_str(), s.part.c_str(), s.what.c_str());
      return 0;
    }
    std::vector<Run> runs;
    fs::create_directories(o.results_dir);
    const bool scaling = o.part == "scaling";
    std::ofstream csv(fs::path(o.results_dir) /
                      ((scaling ? "project-scaling" : "project") + named + "-runs.csv"));
    csv << "part,project,seed,scans,correct,unregistered,confident_misses,refused,worst_rmse_m,links,accepted,loops,"
           "loops_inconsistent,seconds,ambiguous,ambiguous_preferred_right,note\n";
    for (const Suite& s : suites) {
      if (!o.selected(s.part, s.name)) continue;
      for (int seed = 1; seed <= o.seeds; ++seed) {
        const Run r = run_one(s, seed, geometry_only ? k4reg::FreeSpaceCheck::kOff : k4reg::FreeSpaceCheck::kAuto);
        runs.push_back(r);
        std::printf("%-9s %-22s seed %d: %zu/%zu correct, %zu unregistered, %zu CONFIDENT MISSES, worst %.3g m, links %zu/%zu, "
                    "loops %zu (%zu open), %.1f s%s\n",
                    r.part.c_str(), r.suite.c_str(), seed, r.correct, r.scans, r.unregistered, r.confident_misses,
                    r.worst_rmse_m, r.accepted, r.links, r.loops, r.inconsistent, r.seconds, r.note.c_str());
        std::fflush(stdout);
        csv << r.part << ',' << r.suite << ',' << seed << ',' << r.scans << ',' << r.correct << ',' << r.unregistered << ','
            << r.confident_misses << ',' << r.refused << ',' << r.worst_rmse_m << ',' << r.links << ',' << r.accepted << ','
            << r.loops << ',' << r.inconsistent << ',' << r.seconds << ',' << r.ambiguous << ','
            << r.ambiguous_preferred_right << ",\"" << r.note << "\"\n";
      }
    }
    const std::string table = scaling ? scaling_report(runs) : report(suites, runs);
    std::printf("\n%s", table.c_str());
    if (!o.markdown.empty()) replace_block(o.markdown, (scaling ? "project-scaling" : "project") + named, table);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "k4reg-bench-project: %s\n", e.what());
    return 1;
  }
  return 0;
}
