#include "reports/qa_report.h"

#include <filesystem>

#include "report_document.h"

namespace k4reg::cli {
namespace {

std::string file_name(const std::string& path) { return std::filesystem::path(path).filename().string(); }

}  // namespace

PreviewParams ReportFlags::preview() const {
  PreviewParams params;
  params.max_points = preview_points;
  return params;
}

void add_report_flags(CLI::App& command, ReportFlags& flags) {
  command.add_option("--report", flags.path,
                     "write a self-contained HTML QA report (3D view, slices, residuals, hypotheses or links) to this file");
  command.add_option("--report-points", flags.preview_points,
                     "points of the registered clouds the report shows, in all (about 21 bytes each in the file)")
      ->check(CLI::Range(std::size_t{1}, kMaxPreviewPoints))
      ->capture_default_str();
}

nlohmann::json params_to_json(const RegistrationParams& p) {
  const char* signals[] = {"auto", "intensity", "geometric"};
  const char* methods[] = {"keypoint-4pcs", "plain-4pcs"};
  const char* free_space[] = {"auto", "on", "off"};
  return {{"min_scale_m", p.min_scale_m},
          {"overlap", p.overlap},
          {"octaves", p.octaves},
          {"scales_per_octave", p.scales_per_octave},
          {"min_contrast", p.min_contrast},
          {"signal", signals[static_cast<int>(p.signal)]},
          {"method", methods[static_cast<int>(p.method)]},
          {"plain_voxel_m", p.plain_voxel_m},
          {"max_bases", p.max_bases},
          {"hypotheses_kept", p.hypotheses_kept},
          {"free_space", free_space[static_cast<int>(p.free_space)]},
          {"levelled", p.levelled},
          {"search_other_side", p.search_other_side},
          {"icp", p.icp},
          {"icp_max_iterations", p.icp_max_iterations},
          {"seed", p.seed},
          {"threads", p.threads},
          {"time_budget_s", p.time_budget_s}};
}

void write_pair_report(const ReportFlags& flags, const std::string& generator, const std::string& source,
                       const std::string& target, const RegistrationParams& params, const nlohmann::json& result,
                       const CloudPreview* preview) {
  web::ReportDocument document;
  document.kind = "pair";
  document.title = file_name(source) + " -> " + file_name(target);
  document.generator = generator;
  document.files = {source, target};
  document.parameters = params_to_json(params);
  document.result = result;
  document.preview = preview;
  web::write_report(flags.path, document);
}

void write_project_report(const ReportFlags& flags, const std::string& generator, const std::vector<std::string>& scans,
                          const ProjectParams& params, const nlohmann::json& result, const CloudPreview* preview) {
  web::ReportDocument document;
  document.kind = "project";
  document.title = std::to_string(scans.size()) + " scans";
  document.generator = generator;
  document.files = scans;
  document.parameters = params_to_json(params.pairwise);
  document.parameters["reference"] = params.reference;
  document.parameters["pairs"] = to_string(params.pairs);
  document.parameters["partners"] = params.partners;
  document.result = result;
  document.preview = preview;
  web::write_report(flags.path, document);
}

}  // namespace k4reg::cli
