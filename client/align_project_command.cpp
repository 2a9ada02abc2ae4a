#include "align_project_command.h"

#include <fmt/format.h>
#include <unistd.h>

#include <filesystem>
#include <iostream>
#include <memory>
#include <set>

#include "command_error.h"
#include "k4reg/io/cloud_io.h"
#include "k4reg/project/project_registration.h"
#include "project_report.h"
#include "registration_flags.h"

namespace k4reg::cli {
namespace {

struct AlignProjectOptions {
  std::vector<std::string> scans;
  std::string pairs = "all";
  std::string out_dir;
  bool json = false;
  ProjectParams params;
};

void run_align_project(AlignProjectOptions& o) {
  std::set<std::string> seen;
  for (const std::string& file : o.scans)
    if (!seen.insert(std::filesystem::weakly_canonical(file).string()).second)
      throw CommandError(fmt::format("{} is given twice: each scan once", file));
  if (o.pairs == "all")
    o.params.pairs = PairSelection::kAll;
  else if (o.pairs == "sequence")
    o.params.pairs = PairSelection::kSequence;
  else {
    o.params.pairs = PairSelection::kList;
    o.params.pair_list = read_pair_list(o.pairs);
  }

  std::vector<PointCloud> clouds;
  for (const std::string& file : o.scans) clouds.push_back(read_cloud(file));
  // Pair by pair on stderr when someone watches; stdout stays the result.
  const bool watched = isatty(STDERR_FILENO);
  const ProjectResult result = register_project(
      clouds, o.params, nullptr, {}, [&](const ProjectLink& link, std::size_t index, std::size_t pairs) {
        if (!watched) return;
        std::cerr << fmt::format("pair {}/{}: scan {} -> {}: {:.1f} s{}\n", index + 1, pairs, link.source, link.target,
                                 link.seconds, link.verdict == "failed" ? " (failed: " + link.reason + ")" : "");
      });
  const nlohmann::json json = project_to_json(result, o.scans, o.params);
  if (!o.out_dir.empty()) write_project_dir(o.out_dir, result, o.scans, json);
  if (o.json)
    std::cout << json.dump(2) << "\n";
  else
    print_project_table(std::cout, result, o.scans);
}

}  // namespace

void add_align_project_command(CLI::App& app) {
  auto options = std::make_shared<AlignProjectOptions>();
  CLI::App* command = app.add_subcommand(
      "align-project", "register a project of scans into the frame of one of them, locally (no server)");
  command->add_option("SCAN", options->scans, "the scans (PLY, PCD, XYZ/TXT/PTS, LAS, PTX, E57), at least 2")
      ->required()
      ->check(CLI::ExistingFile);
  add_registration_flags(*command, options->params.pairwise);
  command->add_option("--reference", options->params.reference, "0-based index of the scan whose pose is the identity")
      ->capture_default_str();
  command->add_option("--pairs", options->pairs,
                      "which pairs to register: all, sequence (each scan with the next two), or a file of index pairs")
      ->capture_default_str();
  command->add_flag("--json", options->json, "print the result as JSON");
  command->add_option("--out-dir", options->out_dir, "write NAME.pose.txt per registered scan and project.json here");
  command->callback([options] { run_align_project(*options); });
}

}  // namespace k4reg::cli
