#include "commands/align_command.h"

#include <Eigen/LU>
#include <iostream>
#include <memory>
#include <optional>

#include "k4reg/io/cloud_io.h"
#include "k4reg/io/matrix_file.h"
#include "k4reg/registration/metrics.h"
#include "reports/qa_report.h"
#include "commands/registration_flags.h"
#include "reports/result_report.h"

namespace k4reg::cli {
namespace {

struct AlignOptions {
  std::string source, target, out, gt_source, gt_target;
  std::string source_scan, target_scan;  // multi-scan files: an index or an E57 scan name; "" = all scans
  bool json = false;
  double success_rmse_m = kIndoorSuccessRmse_m;
  RegistrationParams params;
  ReportFlags report;
};

// A number selects a scan by its 0-based index, anything else by its name.
ReadOptions scan_selection(const std::string& scan) {
  ReadOptions options;
  if (scan.empty()) return options;
  if (scan.find_first_not_of("0123456789") == std::string::npos && scan.size() < 10)
    options.scan_index = std::stoul(scan);
  else
    options.scan_name = scan;
  return options;
}

void run_align(const AlignOptions& o) {
  const PointCloud source = read_cloud(o.source, scan_selection(o.source_scan));
  const PointCloud target = read_cloud(o.target, scan_selection(o.target_scan));
  const RegistrationResult result = register_clouds(source, target, o.params);
  if (!o.out.empty()) write_matrix4(o.out, result.transform);

  nlohmann::json json = result_to_json(result);
  std::optional<std::pair<TransformError, bool>> checked;  // against ground truth: the error, and success
  if (!o.gt_source.empty()) {
    // Ground truth maps each scan into the scene: source -> target is inv(G_target) * G_source.
    const Eigen::Matrix4d truth = read_matrix4(o.gt_target).inverse() * read_matrix4(o.gt_source);
    Eigen::Matrix4d shift = Eigen::Matrix4d::Identity();  // the metrics take the source's local points
    shift.topRightCorner<3, 1>() = source.origin_m;
    const TransformError error = transform_error(source.points, result.transform * shift, truth * shift);
    checked.emplace(error, registration_succeeded(error, o.success_rmse_m));
    json["ground_truth"] = error_to_json(error, checked->second);
  }
  if (o.report.wanted()) {
    const CloudPreview preview = make_pair_preview(source, target, result, o.report.preview());
    write_pair_report(o.report, "k4reg align", o.source, o.target, o.params, json, &preview);
  }
  if (o.json) {
    std::cout << json.dump(2) << "\n";
    return;
  }
  print_result_table(std::cout, result);
  if (checked) print_error_table(std::cout, checked->first, checked->second);
}

}  // namespace

void add_align_command(CLI::App& app) {
  auto options = std::make_shared<AlignOptions>();
  CLI::App* align = app.add_subcommand("align", "register SOURCE onto TARGET locally (no server)");
  align->add_option("SOURCE", options->source, "source scan (PLY, PCD, XYZ/TXT/PTS, LAS, PTX, E57)")->required()->check(CLI::ExistingFile);
  align->add_option("TARGET", options->target, "target scan")->required()->check(CLI::ExistingFile);
  align->add_option("--source-scan", options->source_scan,
                    "multi-scan SOURCE (E57, PTX): the scan's 0-based index or E57 name (default: all scans merged)");
  align->add_option("--target-scan", options->target_scan, "multi-scan TARGET: index or E57 name, as --source-scan");
  add_registration_flags(*align, options->params);
  align->add_flag("--json", options->json, "print the result as JSON");
  align->add_option("--out", options->out, "write the 4x4 source->target matrix to this file");
  add_report_flags(*align, options->report);
  auto* gs = align->add_option("--gt-source", options->gt_source, "ground truth of the source (simulator .gt.txt)")
                 ->check(CLI::ExistingFile);
  auto* gt = align->add_option("--gt-target", options->gt_target, "ground truth of the target")->check(CLI::ExistingFile);
  gs->needs(gt);
  gt->needs(gs);
  align->add_option("--success-rmse", options->success_rmse_m,
                    "RMSE against ground truth below which a run counts as a success (paper: 0.5 indoor, 1 outdoor)")
      ->capture_default_str();
  align->callback([options] { run_align(*options); });
}

}  // namespace k4reg::cli
