#include "commands/align_project_command.h"

#include <fmt/format.h>

#include <filesystem>
#include <iostream>
#include <memory>
#include <set>

#include "commands/command_error.h"
#include "k4reg/io/cloud_io.h"
#include "k4reg/project/project_registration.h"
#include "commands/project_flags.h"
#include "reports/project_report.h"
#include "reports/qa_report.h"
#include "commands/registration_flags.h"

namespace k4reg::cli {
namespace {

struct AlignProjectOptions {
  std::vector<std::string> scans;
  std::string write_e57;
  ProjectFlags flags;
  ProjectParams params;
  ReportFlags report;
};

void run_align_project(AlignProjectOptions& o) {
  std::set<std::string> seen;
  for (const std::string& file : o.scans)
    if (!seen.insert(std::filesystem::weakly_canonical(file).string()).second)
      throw CommandError(fmt::format("{} is given twice: each scan once", file));
  apply_pairs(o.flags, o.params);

  // A multi-scan E57 or PTX file counts as its scans, each read in its own scanner frame.
  std::vector<PointCloud> clouds;
  std::vector<ScanOrigin> origins;
  for (const std::string& file : o.scans) {
    const std::size_t scans = count_scans(file);
    for (std::size_t k = 0; k < scans; ++k) {
      ReadOptions options;
      if (scans > 1) options.scan_index = k;
      options.apply_pose = false;
      clouds.push_back(read_cloud(file, options));
      origins.push_back({file, scans > 1 ? static_cast<int>(k) : -1});
    }
  }
  // Pair by pair on stderr (a script that keeps the JSON on stdout still sees long work advance); stdout stays the
  // result.
  const ProjectResult result = register_project(
      clouds, o.params, nullptr, {}, [&](const ProjectLink& link, std::size_t index, std::size_t pairs) {
        if (o.flags.quiet) return;
        std::cerr << pair_line(index, pairs, link.source, link.target, link.seconds,
                               link.verdict == LinkVerdict::kFailed ? link.reason : "")
                  << "\n";
      });
  const nlohmann::json json = project_to_json(result, origins, o.params);
  if (!o.flags.out_dir.empty()) write_project_dir(o.flags.out_dir, result, origins, json);
  if (!o.write_e57.empty()) {
    const std::size_t skipped = write_project_e57(o.write_e57, result, clouds, origins);
    if (skipped > 0)
      std::cerr << fmt::format("k4reg: {} unregistered scan{} left out of {}\n", skipped, skipped == 1 ? "" : "s", o.write_e57);
  }
  if (o.report.wanted()) {
    std::vector<std::string> labels;
    for (const ScanOrigin& origin : origins) labels.push_back(origin.label());
    const CloudPreview preview = make_project_preview(clouds, labels, result, o.report.preview());
    write_project_report(o.report, "k4reg align-project", labels, o.params, json, &preview);
  }
  if (o.flags.json)
    std::cout << json.dump(2) << "\n";
  else
    print_project_table(std::cout, result, origins);
}

}  // namespace

void add_align_project_command(CLI::App& app) {
  auto options = std::make_shared<AlignProjectOptions>();
  CLI::App* command = app.add_subcommand(
      "align-project", "register a project of scans into the frame of one of them, locally (no server)");
  command->add_option("SCAN", options->scans,
                      "the scans (PLY, PCD, XYZ/TXT/PTS, LAS, PTX, E57; a multi-scan E57 or PTX file counts as its "
                      "scans), at least 2 in all")
      ->required()
      ->check(CLI::ExistingFile);
  add_registration_flags(*command, options->params.pairwise);
  add_project_flags(*command, options->flags, options->params);
  command->add_option("--write-e57", options->write_e57,
                      "write every registered scan, in its own frame with its pose, to this E57 file (a registered "
                      "project for Cyclone, SCENE, ReCap, CloudCompare)");
  add_report_flags(*command, options->report);
  command->callback([options] { run_align_project(*options); });
}

}  // namespace k4reg::cli
