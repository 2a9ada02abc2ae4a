#include "k4reg/project/scan_conflicts.h"

#include <fmt/format.h>

#include "k4reg/geometry/rigid_motion.h"
#include "k4reg/project/loop_closure.h"
#include "k4reg/project/pose_graph.h"

namespace k4reg {

void refuse_conflicted_scans(ProjectResult& r, const std::vector<double>& scan_radius_m) {
  std::vector<std::string> reasons(r.scans.size());
  for (std::size_t l = 0; l < r.links.size(); ++l) {
    const ProjectLink& link = r.links[l];
    if (link.accepted || link.verdict == "failed" || link.ambiguous || !link.well_supported) continue;
    if (!r.scans[link.source].registered || !r.scans[link.target].registered) continue;
    const double misfit = displacement_m(link_misfit(r.scans[link.source].pose, r.scans[link.target].pose, link.transform),
                                         scan_radius_m.at(link.source));
    if (misfit <= kLoopToleranceFactor * link_tolerance_m(link)) continue;
    for (std::size_t scan : {link.source, link.target})
      if (scan != r.reference && reasons[scan].empty())
        reasons[scan] = fmt::format(
            "in conflict: link {} ({} -> {}), a confident pairwise result, puts it {:.3g} m from where the other links do",
            l, link.source, link.target, misfit);
  }
  for (std::size_t i = 0; i < r.scans.size(); ++i)
    if (!reasons[i].empty()) {
      r.scans[i].registered = false;
      r.scans[i].reason = reasons[i];
    }
}

}  // namespace k4reg
