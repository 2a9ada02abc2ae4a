#include "remote/project_mapping.h"

#include "messages_to_core.h"
#include "pair_selection.h"
#include "remote/proto_mapping.h"

namespace k4reg::cli {

ProjectResult project_result_from_proto(const v1::ProjectResult& m) {
  ProjectResult r;
  for (const v1::ProjectScan& s : m.scans()) {
    ProjectScan scan;
    scan.registered = s.registered();
    if (s.pose_size() == 16) scan.pose = api::matrix_from_proto(s.pose());
    scan.links.assign(s.links().begin(), s.links().end());
    scan.points = s.points();
    scan.strength = s.strength();
    scan.constraint = api::constraint_from_proto(s.constraint());
    scan.reason = s.reason();
    scan.ambiguous = s.ambiguous();
    for (const v1::ScanPlacement& placement : s.candidate_poses())
      if (placement.pose_size() == 16) scan.candidate_poses.push_back(api::matrix_from_proto(placement.pose()));
    scan.scanner_position = api::scanner_from_proto(s.scanner_position());
    r.scans.push_back(std::move(scan));
  }
  for (const v1::ProjectLink& l : m.links()) {
    ProjectLink link;
    link.source = l.source();
    link.target = l.target();
    if (l.transform_size() == 16) link.transform = api::matrix_from_proto(l.transform());
    link.rmse_m = l.rmse_m();
    link.overlap = l.overlap();
    link.cloud_score = l.cloud_score();
    link.ambiguity_margin = l.ambiguity_margin();
    link.ambiguous = l.ambiguous();
    link.well_supported = l.well_supported();
    link.accepted = l.accepted();
    link.verdict = link_verdict_from_string(l.verdict());
    link.reason = l.reason();
    link.loops = l.loops();
    link.loops_closed = l.loops_closed();
    link.loop_residual_m = l.loop_residual_m();
    link.residual_m = l.residual_m();
    link.hypotheses = l.hypotheses();
    link.candidate = l.candidate();
    link.min_scale_m_used = l.min_scale_m_used();
    link.overlap_used = l.overlap_used();
    link.seconds = l.seconds();
    link.judged_loop_poses = l.judged_loop_poses();
    link.loop_pose_won = l.loop_pose_won();
    link.reverse_judged = l.reverse_judged();
    link.reverse_margin = l.reverse_margin();
    link.two_sided_margin = l.two_sided_margin();
    link.runner_up_preferred = l.runner_up_preferred();
    link.constraint = api::constraint_from_proto(l.constraint());
    r.links.push_back(std::move(link));
  }
  r.reference = m.reference();
  r.scans_registered = m.scans_registered();
  r.loops_checked = m.loops_checked();
  r.loops_inconsistent = m.loops_inconsistent();
  r.global_rmse_m = m.global_rmse_m();
  r.pairs_used = api::pair_selection_from_proto(m.pairs_used());
  r.pairs_screened = m.pairs_screened();
  for (const v1::StageTiming& t : m.timings()) r.timings.push_back({t.stage(), t.seconds()});
  return r;
}

}  // namespace k4reg::cli
