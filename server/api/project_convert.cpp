#include "api/project_convert.h"

#include "k4reg/util/error.h"
#include "pair_selection.h"
#include "api/proto_convert.h"

namespace k4reg::service {

ProjectParams project_params_from_proto(const v1::ProjectParams& m) {
  ProjectParams p;
  try {
    p.pairwise = params_from_proto(m.pairwise());
  } catch (const Error& e) {
    // "params.overlap ..." -> "params.pairwise.overlap ..."
    const std::string message = e.what();
    throw Error(e.code(), message.rfind("params.", 0) == 0 ? "params.pairwise." + message.substr(7) : message);
  }
  if (m.has_reference()) p.reference = m.reference();
  p.pairs = api::pair_selection_from_proto(m.pairs());
  if (p.pairs != PairSelection::kList && m.pair_list_size() > 0)
    fail(ErrorCode::kInvalidArgument, "params.pair_list is only for pairs = PAIR_SELECTION_LIST");
  for (const v1::ScanPair& pair : m.pair_list()) p.pair_list.emplace_back(pair.first(), pair.second());
  if (m.has_partners()) {
    if (m.partners() == 0) fail(ErrorCode::kInvalidArgument, "params.partners must be at least 1");
    p.partners = m.partners();
  }
  return p;
}

void project_result_to_proto(const ProjectResult& r, const std::vector<std::string>& files, v1::ProjectResult* m) {
  for (std::size_t i = 0; i < r.scans.size(); ++i) {
    const ProjectScan& s = r.scans[i];
    v1::ProjectScan& out = *m->add_scans();
    out.set_file(files.at(i));
    if (s.registered) matrix_to_proto(s.pose, out.mutable_pose());
    out.set_registered(s.registered);
    for (std::size_t l : s.links) out.add_links(static_cast<std::uint32_t>(l));
    out.set_points(s.points);
    out.set_strength(s.strength);
    constraint_to_proto(s.constraint, &out);
    out.set_reason(s.reason);
    out.set_ambiguous(s.ambiguous);
    for (const Eigen::Matrix4d& pose : s.candidate_poses) matrix_to_proto(pose, out.add_candidate_poses()->mutable_pose());
    scanner_to_proto(s.scanner_position, out.mutable_scanner_position());
  }
  for (const ProjectLink& l : r.links) {
    v1::ProjectLink& out = *m->add_links();
    out.set_source(static_cast<std::uint32_t>(l.source));
    out.set_target(static_cast<std::uint32_t>(l.target));
    matrix_to_proto(l.transform, out.mutable_transform());
    out.set_rmse_m(l.rmse_m);
    out.set_overlap(l.overlap);
    out.set_cloud_score(l.cloud_score);
    out.set_ambiguity_margin(l.ambiguity_margin);
    out.set_ambiguous(l.ambiguous);
    out.set_well_supported(l.well_supported);
    out.set_accepted(l.accepted);
    out.set_verdict(to_string(l.verdict));
    out.set_reason(l.reason);
    out.set_loops(l.loops);
    out.set_loops_closed(l.loops_closed);
    out.set_loop_residual_m(l.loop_residual_m);
    out.set_residual_m(l.residual_m);
    out.set_hypotheses(static_cast<std::uint32_t>(l.hypotheses));
    out.set_candidate(l.candidate);
    out.set_min_scale_m_used(l.min_scale_m_used);
    out.set_overlap_used(l.overlap_used);
    out.set_seconds(l.seconds);
    out.set_judged_loop_poses(static_cast<std::uint32_t>(l.judged_loop_poses));
    out.set_loop_pose_won(l.loop_pose_won);
    out.set_reverse_judged(l.reverse_judged);
    out.set_reverse_margin(l.reverse_margin);
    out.set_two_sided_margin(l.two_sided_margin);
    out.set_runner_up_preferred(l.runner_up_preferred);
    constraint_to_proto(l.constraint, &out);
  }
  m->set_reference(static_cast<std::uint32_t>(r.reference));
  m->set_scans_registered(static_cast<std::uint32_t>(r.scans_registered));
  m->set_loops_checked(static_cast<std::uint32_t>(r.loops_checked));
  m->set_loops_inconsistent(static_cast<std::uint32_t>(r.loops_inconsistent));
  m->set_global_rmse_m(r.global_rmse_m);
  m->set_pairs_used(api::pair_selection_to_proto(r.pairs_used));
  m->set_pairs_screened(static_cast<std::uint32_t>(r.pairs_screened));
  for (const StageTiming& t : r.timings) {
    v1::StageTiming& out = *m->add_timings();
    out.set_stage(t.stage);
    out.set_seconds(t.seconds);
  }
}

void pair_event_to_proto(const ProjectLink& link, std::size_t index, std::size_t pairs, v1::PairEvent& event) {
  event.set_index(static_cast<std::uint32_t>(index));
  event.set_pairs(static_cast<std::uint32_t>(pairs));
  event.set_source(static_cast<std::uint32_t>(link.source));
  event.set_target(static_cast<std::uint32_t>(link.target));
  event.set_seconds(link.seconds);
  if (link.verdict == LinkVerdict::kFailed) event.set_error(link.reason);
}

}  // namespace k4reg::service
