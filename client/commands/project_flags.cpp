#include "commands/project_flags.h"

#include <fmt/format.h>

namespace k4reg::cli {

void add_project_flags(CLI::App& command, ProjectFlags& flags, ProjectParams& params) {
  flags.reference = command.add_option("--reference", params.reference, "0-based index of the scan whose pose is the identity")
                        ->capture_default_str();
  command.add_option("--pairs", flags.pairs,
                     "which pairs to register: auto (all up to " + std::to_string(kAllPairsUpTo) +
                         " scans, screened beyond), all, sequence (each scan with the next two), screened (each scan's "
                         "best partners by a cheap overlap estimate of every pair), or a file of index pairs")
      ->capture_default_str();
  flags.partners = command.add_option("--partners", params.partners, "with screened pairs: partners registered per scan")
                       ->check(CLI::Range(std::size_t{1}, std::size_t{1000000}).description(""))
                       ->capture_default_str();
  command.add_flag("--json", flags.json, "print the result as JSON");
  command.add_flag("--quiet", flags.quiet, "no line per finished pair on stderr (stdout is the result either way)");
  command.add_option("--out-dir", flags.out_dir, "write NAME.pose.txt per registered scan and project.json here");
}

void apply_pairs(const ProjectFlags& flags, ProjectParams& params) {
  // "list" names no file: a file of that name is read as one.
  const std::optional<PairSelection> named = pair_selection_named(flags.pairs);
  if (named && named != PairSelection::kList) {
    params.pairs = *named;
  } else {
    params.pairs = PairSelection::kList;
    params.pair_list = read_pair_list(flags.pairs);
  }
}

std::string pair_line(std::size_t index, std::size_t pairs, std::size_t source, std::size_t target, double seconds,
                      const std::string& error) {
  return fmt::format("pair {}/{}: scan {} -> {}: {:.1f} s{}", index + 1, pairs, source, target, seconds,
                     error.empty() ? "" : " (failed: " + error + ")");
}

}  // namespace k4reg::cli
