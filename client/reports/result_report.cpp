#include "reports/result_report.h"

#include <fmt/format.h>

#include "k4reg/io/matrix_file.h"
#include "k4reg/registration/translation_constraint.h"

namespace k4reg::cli {

nlohmann::json matrix_to_json(const Eigen::Matrix4d& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) rows.push_back(m(r, c));
  return rows;  // row-major, 16 numbers
}

nlohmann::json points_to_json(const std::vector<Eigen::Vector3d>& points) {
  nlohmann::json values = nlohmann::json::array();
  for (const Eigen::Vector3d& p : points) values.insert(values.end(), {p.x(), p.y(), p.z()});
  return values;  // x, y, z of each point in turn
}

nlohmann::json scanner_to_json(const ScannerPosition& s) {
  nlohmann::json point = nlohmann::json::array();
  if (s.source != ScannerSource::kNone) point = {s.position_m.x(), s.position_m.y(), s.position_m.z()};
  return {{"point_m", point},
          {"source", to_string(s.source)},
          {"fit", s.fit.share},
          {"angular_step_rad", s.fit.step_rad},
          {"reason", s.reason}};
}

std::string scanner_to_text(const ScannerPosition& s) {
  if (s.source == ScannerSource::kNone) return "none: " + s.reason;
  return fmt::format("{} ({:.3f}, {:.3f}, {:.3f}) m, fit {:.2f}", to_string(s.source), s.position_m.x(), s.position_m.y(),
                     s.position_m.z(), s.fit.share);
}

nlohmann::json result_to_json(const RegistrationResult& r) {
  nlohmann::json j;
  j["transform"] = matrix_to_json(r.transform);
  j["rmse_m"] = r.rmse_m;
  j["overlap"] = r.overlap;
  j["inliers"] = r.inliers;
  j["source_points"] = r.source_points;
  j["target_points"] = r.target_points;
  j["source_voxels"] = r.source_voxels;
  j["target_voxels"] = r.target_voxels;
  j["source_keypoints"] = r.source_keypoints;
  j["target_keypoints"] = r.target_keypoints;
  j["signal"] = r.signal;
  j["ambiguity_margin"] = r.ambiguity_margin;
  j["ambiguous"] = r.ambiguous;
  j["ambiguity_reason"] = r.ambiguity_reason;
  j["well_supported"] = r.well_supported;
  j["free_space_used"] = r.free_space_used;
  j["source_scanner_position"] = scanner_to_json(r.source_scanner);
  j["target_scanner_position"] = scanner_to_json(r.target_scanner);
  j["min_scale_m_used"] = r.min_scale_m_used;
  j["overlap_used"] = r.overlap_used;
  j["axis_constraint"] = axis_constraint(r.constraint);
  j["weakest_constraint"] = weakest_constraint(r.constraint);
  j["bases_tried"] = r.bases_tried;
  j["seed"] = r.seed;
  j["icp_converged"] = r.icp_converged;
  j["icp_iterations"] = r.icp_iterations;
  j["hypotheses"] = nlohmann::json::array();
  for (const Hypothesis& h : r.hypotheses)
    j["hypotheses"].push_back(
        {{"transform", matrix_to_json(h.transform)},
         {"keypoint_score", h.keypoint_score},
         {"cloud_score", h.cloud_score},
         {"refined_score", h.refined_score},
         {"surface_agreement", h.surface_agreement},
         {"base_source_m", points_to_json(h.base_source_m)},
         {"base_target_m", points_to_json(h.base_target_m)}});
  j["timings"] = timings_to_json(r.timings);
  return j;
}

nlohmann::json timings_to_json(const std::vector<StageTiming>& timings) {
  nlohmann::json j = nlohmann::json::array();
  for (const StageTiming& t : timings) j.push_back({{"stage", t.stage}, {"seconds", t.seconds}});
  return j;
}

void print_timings(std::ostream& out, const std::vector<StageTiming>& timings) {
  double total = 0;
  for (const StageTiming& t : timings) {
    out << fmt::format("  {:<20}{:.3f} s\n", t.stage, t.seconds);
    total += t.seconds;
  }
  out << fmt::format("{:<22}{:.3f} s\n", "total", total);
}

void print_result_table(std::ostream& out, const RegistrationResult& r) {
  out << "transform (source -> target):\n" << format_matrix4(r.transform);
  out << fmt::format("{:<22}{:.4f} m\n", "rmse", r.rmse_m);
  out << fmt::format("{:<22}{:.1f} %\n", "overlap", 100.0 * r.overlap);
  out << fmt::format("{:<22}{}\n", "inliers", r.inliers);
  const std::array<double, 3> axis = axis_constraint(r.constraint);
  out << fmt::format("{:<22}x {:.2f}  y {:.2f}  z {:.2f}  (weakest direction {:.2f}; 1 = as firm as the average)\n",
                     "constraint", axis[0], axis[1], axis[2], weakest_constraint(r.constraint));
  out << fmt::format("{:<22}{} / {}\n", "points", r.source_points, r.target_points);
  out << fmt::format("{:<22}{} / {} ({})\n", "keypoints", r.source_keypoints, r.target_keypoints, r.signal);
  out << fmt::format("{:<22}{:.4g} m\n", "min scale used", r.min_scale_m_used);
  out << fmt::format("{:<22}{:.2f}\n", "overlap used", r.overlap_used);
  out << fmt::format("{:<22}{:.3f}\n", "ambiguity margin", r.ambiguity_margin);
  out << fmt::format("{:<22}{}\n", "ambiguous", r.ambiguous ? "yes: " + r.ambiguity_reason : "no");
  out << fmt::format("{:<22}{}\n", "well supported", r.well_supported ? "yes" : "no");
  out << fmt::format("{:<22}{}\n", "free space used", r.free_space_used ? "yes" : "no (geometry alone)");
  out << fmt::format("{:<22}{}\n", "source scanner", scanner_to_text(r.source_scanner));
  out << fmt::format("{:<22}{}\n", "target scanner", scanner_to_text(r.target_scanner));
  out << fmt::format("{:<22}{}\n", "hypotheses", r.hypotheses.size());
  for (std::size_t k = 0; k < r.hypotheses.size(); ++k) {
    const Hypothesis& h = r.hypotheses[k];
    out << fmt::format("  #{}  cloud score {:.3f}  keypoint score {:.3f}", k + 1, h.cloud_score, h.keypoint_score);
    if (h.refined_score > 0)
      out << fmt::format("  refined score {:.3f}  surface agreement {:.2f}", h.refined_score, h.surface_agreement);
    out << "\n";
  }
  out << fmt::format("{:<22}{}\n", "seed", r.seed);
  print_timings(out, r.timings);
}

nlohmann::json error_to_json(const TransformError& e, bool success) {
  return {{"mae_deg", e.mae_deg}, {"mte_m", e.mte_m}, {"rotation_error_deg", e.rotation_deg},
          {"translation_error_m", e.translation_m}, {"rmse_m", e.rmse_m}, {"success", success}};
}

void print_error_table(std::ostream& out, const TransformError& e, bool success) {
  out << "against ground truth:\n";
  out << fmt::format("  {:<20}{:.4f} deg\n", "MAE", e.mae_deg);
  out << fmt::format("  {:<20}{:.4f} m\n", "MTE", e.mte_m);
  out << fmt::format("  {:<20}{:.4f} deg\n", "rotation error", e.rotation_deg);
  out << fmt::format("  {:<20}{:.4f} m\n", "translation error", e.translation_m);
  out << fmt::format("  {:<20}{:.4f} m\n", "RMSE", e.rmse_m);
  out << fmt::format("  {:<20}{}\n", "success", success ? "yes" : "no");
}

}  // namespace k4reg::cli
