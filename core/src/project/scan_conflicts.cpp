#include "k4reg/project/scan_conflicts.h"

#include <fmt/format.h>

#include "k4reg/geometry/rigid_motion.h"
#include "k4reg/project/loop_closure.h"
#include "k4reg/project/pose_graph.h"

namespace k4reg {

void refuse_conflicted_scans(ProjectResult& r, const std::vector<ScanExtent>& extents) {
  std::vector<std::size_t> holding(r.scans.size(), 0), contradicting(r.scans.size(), 0);
  std::vector<std::string> reasons(r.scans.size());
  for (const ProjectLink& link : r.links)
    if (link.accepted) ++holding[link.source], ++holding[link.target];
  for (std::size_t l = 0; l < r.links.size(); ++l) {
    const ProjectLink& link = r.links[l];
    if (link.accepted || link.verdict == LinkVerdict::kFailed || link.ambiguous || !link.well_supported) continue;
    if (!r.scans[link.source].registered || !r.scans[link.target].registered) continue;
    const double misfit = displacement_m(link_misfit(r.scans[link.source].pose, r.scans[link.target].pose, link.transform),
                                         extents.at(link.source));
    if (misfit <= kLoopToleranceFactor * link_tolerance_m(link)) continue;
    for (std::size_t scan : {link.source, link.target}) {
      ++contradicting[scan];
      if (reasons[scan].empty())
        reasons[scan] = fmt::format(
            "in conflict: link {} ({} -> {}), a confident pairwise result, puts it {:.3g} m from where the other links do",
            l, link.source, link.target, misfit);
    }
  }
  for (std::size_t i = 0; i < r.scans.size(); ++i)
    if (i != r.reference && contradicting[i] > 0 && contradicting[i] >= holding[i]) {
      r.scans[i].registered = false;
      r.scans[i].reason = reasons[i] + fmt::format(" ({} such links against the {} accepted ones that place it)",
                                                   contradicting[i], holding[i]);
    }
}

void refuse_minority_placements(ProjectResult& r) {
  for (bool changed = true; changed;) {
    changed = false;
    for (std::size_t i = 0; i < r.scans.size(); ++i) {
      ProjectScan& scan = r.scans[i];
      if (!scan.registered || i == r.reference) continue;
      std::size_t held = 0;
      for (std::size_t l : scan.links) {
        const ProjectLink& link = r.links[l];
        held += r.scans[link.source == i ? link.target : link.source].registered;
      }
      if (2 * held > scan.links.size()) continue;
      scan.registered = false;
      scan.reason = fmt::format(
          "placed on a minority of its evidence: {} of its {} accepted links lead to scans the project refused", scan.links.size() - held,
          scan.links.size());
      changed = true;
    }
  }
}

}  // namespace k4reg
