#include "reports/project_report.h"

#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <set>

#include "k4reg/io/e57_io.h"
#include "k4reg/io/matrix_file.h"
#include "k4reg/registration/translation_constraint.h"
#include "k4reg/util/error.h"
#include "reports/result_report.h"

namespace k4reg::cli {

std::string ScanOrigin::label() const { return scan < 0 ? file : fmt::format("{}#{}", file, scan); }

nlohmann::json project_to_json(const ProjectResult& r, const std::vector<ScanOrigin>& origins, const ProjectParams& params) {
  nlohmann::json j;
  j["scans"] = nlohmann::json::array();
  for (std::size_t i = 0; i < r.scans.size(); ++i) {
    const ProjectScan& s = r.scans[i];
    nlohmann::json candidate_poses = nlohmann::json::array();
    for (const Eigen::Matrix4d& pose : s.candidate_poses) candidate_poses.push_back({{"pose", matrix_to_json(pose)}});  // as the proto's JSON
    j["scans"].push_back({{"file", origins.at(i).file},
                          {"scan_in_file", origins.at(i).scan},
                          {"pose", s.registered ? matrix_to_json(s.pose) : nlohmann::json(nullptr)},
                          {"registered", s.registered},
                          {"links", s.links},
                          {"points", s.points},
                          {"strength", s.strength},
                          {"axis_constraint", axis_constraint(s.constraint)},
                          {"weakest_constraint", weakest_constraint(s.constraint)},
                          {"reason", s.reason},
                          {"ambiguous", s.ambiguous},
                          {"candidate_poses", candidate_poses},
                          {"scanner_position", scanner_to_json(s.scanner_position)}});
  }
  j["links"] = nlohmann::json::array();
  for (const ProjectLink& l : r.links)
    j["links"].push_back({{"source", l.source},
                          {"target", l.target},
                          {"transform", matrix_to_json(l.transform)},
                          {"rmse_m", l.rmse_m},
                          {"overlap", l.overlap},
                          {"cloud_score", l.cloud_score},
                          {"ambiguity_margin", l.ambiguity_margin},
                          {"ambiguous", l.ambiguous},
                          {"well_supported", l.well_supported},
                          {"accepted", l.accepted},
                          {"verdict", to_string(l.verdict)},
                          {"reason", l.reason},
                          {"loops", l.loops},
                          {"loops_closed", l.loops_closed},
                          {"loop_residual_m", l.loop_residual_m},
                          {"residual_m", l.residual_m},
                          {"hypotheses", l.hypotheses},
                          {"candidate", l.candidate},
                          {"min_scale_m_used", l.min_scale_m_used},
                          {"overlap_used", l.overlap_used},
                          {"seconds", l.seconds},
                          {"judged_loop_poses", l.judged_loop_poses},
                          {"loop_pose_won", l.loop_pose_won},
                          {"reverse_judged", l.reverse_judged},
                          {"reverse_margin", l.reverse_margin},
                          {"two_sided_margin", l.two_sided_margin},
                          {"runner_up_preferred", l.runner_up_preferred},
                          {"axis_constraint", axis_constraint(l.constraint)},
                          {"weakest_constraint", weakest_constraint(l.constraint)}});
  j["reference"] = r.reference;
  j["scans_registered"] = r.scans_registered;
  j["loops_checked"] = r.loops_checked;
  j["loops_inconsistent"] = r.loops_inconsistent;
  j["global_rmse_m"] = r.global_rmse_m;
  j["pairs_used"] = to_string(r.pairs_used);
  j["pairs_screened"] = r.pairs_screened;
  j["timings"] = timings_to_json(r.timings);
  j["params"] = {{"min_scale_m", params.pairwise.min_scale_m},
                 {"overlap", params.pairwise.overlap},
                 {"reference", params.reference},
                 {"pairs", to_string(params.pairs)},
                 {"partners", params.partners},
                 {"levelled", params.pairwise.levelled},
                 {"seed", params.pairwise.seed}};
  return j;
}

void print_project_table(std::ostream& out, const ProjectResult& r, const std::vector<ScanOrigin>& origins) {
  out << fmt::format("{} of {} scans registered (reference: scan {}, {})\n", r.scans_registered, r.scans.size(),
                     r.reference, origins.at(r.reference).label());
  for (std::size_t i = 0; i < r.scans.size(); ++i) {
    const ProjectScan& s = r.scans[i];
    out << fmt::format("scan {} {}: {}\n", i, origins.at(i).label(),
                       s.registered ? fmt::format("registered (strength {:.3f}, weakest constraint {:.2f})", s.strength,
                                                  weakest_constraint(s.constraint))
                                    : "NOT registered: " + s.reason);
    out << fmt::format("  scanner: {}\n", scanner_to_text(s.scanner_position));
    if (s.registered) out << format_matrix4(s.pose);
    for (std::size_t k = 0; k < s.candidate_poses.size(); ++k)
      out << fmt::format("  candidate placement {}{}:\n", k + 1, k == 0 ? " (its links prefer it)" : " (the twin)")
          << format_matrix4(s.candidate_poses[k]);
  }
  out << fmt::format("{:<6}{:<10}{:>9}{:>9}{:>8}{:>8}{:>12}{:>12}  {}\n", "link", "scans", "rmse m", "overlap", "margin",
                     "loops", "loop res m", "residual m", "verdict");
  for (std::size_t k = 0; k < r.links.size(); ++k) {
    const ProjectLink& l = r.links[k];
    out << fmt::format("{:<6}{:<10}{:>9.4f}{:>8.0f}%{:>8.3f}{:>8}{:>12.4g}{:>12.4g}  {}{}\n", k,
                       fmt::format("{}->{}", l.source, l.target), l.rmse_m, 100 * l.overlap, l.ambiguity_margin,
                       fmt::format("{}/{}", l.loops_closed, l.loops), l.loop_residual_m, l.residual_m,
                       l.accepted ? "accepted" : "REJECTED", l.reason.empty() ? "" : ": " + l.reason);
  }
  out << fmt::format("loops checked {}, inconsistent {}; global rmse {:.4g} m\n", r.loops_checked, r.loops_inconsistent,
                     r.global_rmse_m);
  print_timings(out, r.timings);
}

std::vector<std::string> write_project_dir(const std::string& dir, const ProjectResult& r,
                                           const std::vector<ScanOrigin>& origins, const nlohmann::json& json) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) fail(ErrorCode::kPermissionDenied, dir + ": cannot create the output folder: " + ec.message());
  std::vector<std::string> names;
  std::set<std::string> taken;
  for (std::size_t i = 0; i < r.scans.size(); ++i) {
    if (!r.scans[i].registered) {  // no pose to give: no file that could be mistaken for one
      names.emplace_back();
      continue;
    }
    const ScanOrigin& origin = origins.at(i);
    const std::string stem = std::filesystem::path(origin.file).stem().string() +
                             (origin.scan < 0 ? std::string() : fmt::format("-s{}", origin.scan));
    std::string name = stem + ".pose.txt";
    for (int k = 2; taken.count(name); ++k) name = fmt::format("{}-{}.pose.txt", stem, k);
    taken.insert(name);
    write_matrix4((std::filesystem::path(dir) / name).string(), r.scans[i].pose);
    names.push_back(name);
  }
  const std::string path = (std::filesystem::path(dir) / "project.json").string();
  std::ofstream out(path);
  out << json.dump(2) << "\n";
  if (!out) fail(ErrorCode::kPermissionDenied, path + ": cannot write");
  return names;
}

std::size_t write_project_e57(const std::string& path, const ProjectResult& r, const std::vector<PointCloud>& clouds,
                              const std::vector<ScanOrigin>& origins) {
  std::vector<E57Scan> scans;
  for (std::size_t i = 0; i < r.scans.size(); ++i) {
    if (!r.scans[i].registered) continue;  // no pose to give: left out rather than put at the origin
    E57Scan scan;
    scan.name = std::filesystem::path(origins.at(i).label()).filename().string();
    scan.cloud = clouds.at(i);
    scan.pose = Eigen::Isometry3d(r.scans[i].pose);
    scans.push_back(std::move(scan));
  }
  write_e57(path, scans);
  return r.scans.size() - scans.size();
}

}  // namespace k4reg::cli
