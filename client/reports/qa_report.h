// `--report FILE.html` of align, register, align-project and register-project: the self-contained HTML QA
// report (web/report_document.h) of a pair or a project, with a preview of the registered clouds.
#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "k4reg/project/project_registration.h"
#include "k4reg/qa/cloud_preview.h"

namespace k4reg::cli {

struct ReportFlags {
  std::string path;                  // "" = no report
  std::size_t preview_points = 1000000;  // in all; the report weighs about 21 bytes per point
  bool wanted() const { return !path.empty(); }
  PreviewParams preview() const;
};

void add_report_flags(CLI::App& command, ReportFlags& flags);

// Every parameter of a registration, as used (0 = automatic where the struct says so).
nlohmann::json params_to_json(const RegistrationParams& params);

// `result` as the command's --json prints it; `preview` may be null (the report then shows the figures only).
void write_pair_report(const ReportFlags& flags, const std::string& generator, const std::string& source,
                       const std::string& target, const RegistrationParams& params, const nlohmann::json& result,
                       const CloudPreview* preview);
void write_project_report(const ReportFlags& flags, const std::string& generator, const std::vector<std::string>& scans,
                          const ProjectParams& params, const nlohmann::json& result, const CloudPreview* preview);

}  // namespace k4reg::cli
