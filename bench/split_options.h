// The command-line options of the benchmarks that split their runs into a tuning and a held-out part
// (k4reg-bench-blind, k4reg-bench-project), with the same names and defaults in both.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace k4reg::bench {

struct SplitOptions {
  std::string part = "all", names, data_dir = "../shared/data", cache_dir = "build-bench/bench-cache",
              results_dir = "bench/results", markdown = "bench/RESULTS.md";
  int seeds = 1;
  bool list = false;

  // Adds the options; `block` names the RESULTS.md block the program writes; `extra_part`, if any, is a part of
  // its own that "all" leaves out (a long measurement rather than a check).
  void add_to(CLI::App& app, const std::string& block, const std::string& extra_part = "") {
    std::vector<std::string> parts{"tuning", "held-out", "all"};
    if (!extra_part.empty()) parts.push_back(extra_part);
    app.add_option("--part", part, "tuning, held-out or all" + (extra_part.empty() ? "" : " (or " + extra_part + ")"))
        ->check(CLI::IsMember(parts));
    app.add_option("--suites", names, "comma-separated suite names (default: every suite of the part)");
    app.add_option("--seeds", seeds, "seeds per suite item")->check(CLI::Range(1, 100))->capture_default_str();
    app.add_option("--data-dir", data_dir, "the real data sets (shared/data)");
    app.add_option("--cache-dir", cache_dir, "simulated scans are cached here");
    app.add_option("--results-dir", results_dir, "runs CSV goes here");
    app.add_option("--markdown", markdown, "RESULTS.md to update (block \"" + block + "\"); empty = none");
    app.add_flag("--list", list, "list the suites and exit");
  }
  // Whether a suite of `suite_part` named `name` is to run.
  bool selected(const std::string& suite_part, const std::string& name) const {
    const bool own_part = suite_part == "tuning" || suite_part == "held-out";
    return (suite_part == part || (part == "all" && own_part)) && (names.empty() || ("," + names + ",").find("," + name + ",") != std::string::npos);
  }
};

}  // namespace k4reg::bench
