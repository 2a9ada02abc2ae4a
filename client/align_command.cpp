#include "align_command.h"

#include <Eigen/LU>
#include <iostream>
#include <memory>

#include "k4reg/cloud_io.h"
#include "k4reg/matrix_file.h"
#include "k4reg/metrics.h"
#include "registration_flags.h"
#include "result_report.h"

namespace k4reg::cli {
namespace {

struct AlignOptions {
  std::string source, target, out, gt_source, gt_target;
  bool json = false;
  double success_rmse_m = kIndoorSuccessRmse_m;
  RegistrationParams params;
};

void run_align(const AlignOptions& o) {
  const PointCloud source = read_cloud(o.source);
  const PointCloud target = read_cloud(o.target);
  const RegistrationResult result = register_clouds(source, target, o.params);
  if (!o.out.empty()) write_matrix4(o.out, result.transform);

  nlohmann::json json = result_to_json(result);
  if (!o.gt_source.empty()) {
    // Ground truth maps each scan into the scene: source -> target is inv(G_target) * G_source.
    const Eigen::Matrix4d truth = read_matrix4(o.gt_target).inverse() * read_matrix4(o.gt_source);
    Eigen::Matrix4d shift = Eigen::Matrix4d::Identity();  // the metrics take the source's local points
    shift.topRightCorner<3, 1>() = source.origin_m;
    const TransformError error = transform_error(source.points, result.transform * shift, truth * shift);
    const bool success = registration_succeeded(error, o.success_rmse_m);
    if (o.json) {
      json["ground_truth"] = error_to_json(error, success);
    } else {
      print_result_table(std::cout, result);
      print_error_table(std::cout, error, success);
      return;
    }
  }
  if (o.json)
    std::cout << json.dump(2) << "\n";
  else
    print_result_table(std::cout, result);
}

}  // namespace

void add_align_command(CLI::App& app) {
  auto options = std::make_shared<AlignOptions>();
  CLI::App* align = app.add_subcommand("align", "register SOURCE onto TARGET locally (no server)");
  align->add_option("SOURCE", options->source, "source scan (PLY, PCD, XYZ/TXT/PTS)")->required()->check(CLI::ExistingFile);
  align->add_option("TARGET", options->target, "target scan")->required()->check(CLI::ExistingFile);
  add_registration_flags(*align, options->params);
  align->add_flag("--json", options->json, "print the result as JSON");
  align->add_option("--out", options->out, "write the 4x4 source->target matrix to this file");
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
