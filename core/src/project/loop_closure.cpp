#include "k4reg/project/loop_closure.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <optional>
#include <utility>

#include "k4reg/geometry/rigid_motion.h"
#include "k4reg/registration/ambiguity_margin.h"
#include "k4reg/registration/registration.h"

namespace k4reg {
namespace {

// A triangle of links a -> b -> c -> a: link indices, and whether each is used against its direction.
struct Triangle {
  std::size_t start;  // scan a
  std::array<std::size_t, 3> link;
  std::array<bool, 3> inverted;
};

std::vector<Triangle> find_triangles(const std::vector<LinkCandidates>& links) {
  std::map<std::pair<std::size_t, std::size_t>, std::size_t> by_pair;  // (low, high) scan -> link
  std::size_t scans = 0;
  for (std::size_t i = 0; i < links.size(); ++i) {
    const auto [s, t] = std::minmax(links[i].source, links[i].target);
    by_pair.emplace(std::make_pair(s, t), i);
    scans = std::max(scans, t + 1);
  }
  std::vector<std::vector<std::size_t>> neighbours(scans);
  for (const auto& [pair, link] : by_pair) neighbours[pair.first].push_back(pair.second);  // sorted: map order
  std::vector<Triangle> triangles;
  for (std::size_t a = 0; a < scans; ++a)
    for (std::size_t b : neighbours[a])
      for (std::size_t c : neighbours[b]) {
        const auto closing = by_pair.find({a, c});
        if (closing == by_pair.end()) continue;
        // Walk a -> b -> c -> a; a link is inverted where it maps the other way.
        const std::size_t ab = by_pair.at({a, b}), bc = by_pair.at({b, c}), ca = closing->second;
        triangles.push_back({a, {ab, bc, ca}, {links[ab].source != a, links[bc].source != b, links[ca].source != c}});
      }
  return triangles;
}

// A triangle's residual (metres of displacement where it starts) and tolerance with the candidates `picks`.
std::pair<double, double> loop_residual(const std::vector<LinkCandidates>& links, const Triangle& tri,
                                        const std::array<int, 3>& picks, const std::vector<ScanExtent>& extents) {
  Eigen::Matrix4d loop = Eigen::Matrix4d::Identity();
  double tolerance_sq = 0.0;
  for (int k = 0; k < 3; ++k) {
    const LinkCandidates& link = links[tri.link[k]];
    const Eigen::Matrix4d& t = link.transforms[picks[k]];
    loop = (tri.inverted[k] ? rigid_inverse(t) : t) * loop;
    tolerance_sq += link.tolerance_m * link.tolerance_m;
  }
  return {displacement_m(loop, extents.at(tri.start)), kLoopToleranceFactor * std::sqrt(tolerance_sq)};
}

}  // namespace

std::vector<std::vector<Eigen::Matrix4d>> poses_implied_by_open_loops(const std::vector<LinkCandidates>& links,
                                                                     const LoopSelectionResult& selection,
                                                                     const std::vector<ScanExtent>& extents) {
  auto pick = [&](std::size_t l) {
    return selection.links.at(l).candidate >= 0 ? selection.links[l].candidate : links[l].transforms.empty() ? -1 : 0;
  };
  std::vector<std::vector<Eigen::Matrix4d>> implied(links.size());
  auto known = [&](std::size_t l, const Eigen::Matrix4d& pose) {
    auto near = [&](const Eigen::Matrix4d& t) { return within_loop_tolerance(links[l], t, pose, extents); };
    return std::any_of(links[l].transforms.begin(), links[l].transforms.end(), near) ||
           std::any_of(implied[l].begin(), implied[l].end(), near);
  };
  // Each step of the walk as it is taken; a closed walk has step k = (step k+2 * step k+1)^-1.
  auto imply = [&](const Triangle& tri, const std::array<int, 3>& picks) {
    std::array<Eigen::Matrix4d, 3> step;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Matrix4d& t = links[tri.link[k]].transforms[picks[k]];
      step[k] = tri.inverted[k] ? rigid_inverse(t) : t;
    }
    for (int k = 0; k < 3; ++k) {
      // Only two links whose pairwise winners are well supported imply a pose worth judging.
      if (!links[tri.link[(k + 1) % 3]].well_supported || !links[tri.link[(k + 2) % 3]].well_supported) continue;
      const Eigen::Matrix4d walked = rigid_inverse(step[(k + 2) % 3] * step[(k + 1) % 3]);
      const Eigen::Matrix4d pose = tri.inverted[k] ? rigid_inverse(walked) : walked;
      if (!known(tri.link[k], pose)) implied[tri.link[k]].push_back(pose);
    }
  };
  auto closes = [&](const Triangle& tri, const std::array<int, 3>& picks) {
    const auto [r, tol] = loop_residual(links, tri, picks, extents);
    return r <= tol;
  };
  for (const Triangle& tri : find_triangles(links)) {
    const std::array<int, 3> picks{pick(tri.link[0]), pick(tri.link[1]), pick(tri.link[2])};
    if (std::any_of(picks.begin(), picks.end(), [](int c) { return c < 0; })) continue;
    if (!closes(tri, picks)) imply(tri, picks);
    // A loop closed through a runner-up while the pairwise winners do not close: the runner-up may be a
    // symmetric twin that closes with another link's confident wrong winner (a scan turned against all the
    // others closes every loop). The winners then imply a pose for that link, to be judged too.
    const std::array<int, 3> winners{0, 0, 0};
    if (picks != winners && !closes(tri, winners)) imply(tri, winners);
  }
  return implied;
}

bool within_loop_tolerance(const LinkCandidates& link, const Eigen::Matrix4d& a, const Eigen::Matrix4d& b,
                           const std::vector<ScanExtent>& extents) {
  return displacement_m(rigid_inverse(a) * b, extents.at(link.source)) <= kLoopToleranceFactor * link.tolerance_m;
}

LoopPoseJudgement judge_implied_poses(const LinkCandidates& link, const std::vector<Eigen::Matrix4d>& implied,
                                      const RegistrationResult& judged, const std::vector<ScanExtent>& extents) {
  auto implied_pose = [&](const Eigen::Matrix4d& t) {
    return std::any_of(implied.begin(), implied.end(),
                       [&](const Eigen::Matrix4d& p) { return within_loop_tolerance(link, p, t, extents); });
  };
  if (link.transforms.empty() || judged.hypotheses.empty()) return LoopPoseJudgement::kWinnerStands;
  if (implied_pose(judged.transform) && !within_loop_tolerance(link, link.transforms.front(), judged.transform, extents))
    return LoopPoseJudgement::kImpliedWon;
  const bool tied = judged.ambiguity_margin < ambiguous_below(judged.free_space_used) && judged.hypotheses.size() >= 2 &&
                    judged.hypotheses[1].refined_score > 0 && implied_pose(judged.hypotheses[1].transform);
  return tied ? LoopPoseJudgement::kTied : LoopPoseJudgement::kWinnerStands;
}

LoopSelectionResult select_loop_consistent(const std::vector<LinkCandidates>& links,
                                           const std::vector<ScanExtent>& extents) {
  const std::vector<Triangle> triangles = find_triangles(links);
  std::vector<std::vector<std::size_t>> through(links.size());  // triangles through each link
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (std::size_t l : triangles[t].link) through[l].push_back(t);

  std::vector<int> chosen(links.size(), -1);
  for (std::size_t l = 0; l < links.size(); ++l)
    if (!links[l].transforms.empty()) chosen[l] = 0;

  // A triangle's residual and tolerance with the candidates `picks` on its three links.
  using Picks = std::array<int, 3>;
  auto loop_residual = [&](const Triangle& tri, const Picks& picks) {
    return k4reg::loop_residual(links, tri, picks, extents);
  };
  // Whether the closed loop vouches for its link `self` (see the header); links confirmed by other loops
  // count as certain.
  std::vector<bool> trusted(links.size(), false);
  auto vouches = [&](const Triangle& tri, const Picks& picks, std::size_t self) {
    std::array<double, 3> margins;
    for (int k = 0; k < 3; ++k) {
      const std::size_t m = tri.link[k];
      margins[k] = m != self && trusted[m] ? 1.0 : picks[k] == 0 && links[m].well_supported ? links[m].margin : 0.0;
    }
    std::sort(margins.begin(), margins.end());
    return margins[0] + margins[1] >= kAmbiguousMargin;
  };
  // The current choice on a triangle, with `pick` on link `l`; false when a link of it has no candidate.
  auto picks_with = [&](const Triangle& tri, std::size_t l, int pick, Picks& picks) {
    for (int k = 0; k < 3; ++k) picks[k] = tri.link[k] == l ? pick : chosen[tri.link[k]];
    return std::all_of(picks.begin(), picks.end(), [](int c) { return c >= 0; });
  };
  auto closed_count = [&](std::size_t l, int pick) {
    int closed = 0;
    Picks picks;
    for (std::size_t t : through[l]) {
      if (!picks_with(triangles[t], l, pick, picks)) continue;
      const auto [r, tol] = loop_residual(triangles[t], picks);
      closed += r <= tol && vouches(triangles[t], picks, l);
    }
    return closed;
  };

  // The start: per triangle, the closing and vouching choice nearest the pairwise winners (smallest sum of
  // candidate ranks, among each link's first kJointCandidates); each link takes the candidate most of its
  // triangles chose this way. Changing one link at a time cannot leave a choice where two links of a
  // triangle are wrong; this can.
  constexpr int kJointCandidates = 4;
  std::vector<std::vector<int>> votes(links.size());
  for (std::size_t l = 0; l < links.size(); ++l) votes[l].assign(links[l].transforms.size(), 0);
  for (const Triangle& tri : triangles) {
    std::optional<Picks> best;
    Picks p;
    auto count = [&](std::size_t k) { return std::min<int>(kJointCandidates, links[tri.link[k]].transforms.size()); };
    for (p[0] = 0; p[0] < count(0); ++p[0])
      for (p[1] = 0; p[1] < count(1); ++p[1])
        for (p[2] = 0; p[2] < count(2); ++p[2]) {
          if (best && p[0] + p[1] + p[2] >= (*best)[0] + (*best)[1] + (*best)[2]) continue;
          const auto [r, tol] = loop_residual(tri, p);
          if (r <= tol && vouches(tri, p, links.size())) best = p;
        }
    if (best)
      for (int k = 0; k < 3; ++k) ++votes[tri.link[k]][(*best)[k]];
  }
  for (std::size_t l = 0; l < links.size(); ++l)
    if (!votes[l].empty()) chosen[l] = static_cast<int>(std::max_element(votes[l].begin(), votes[l].end()) - votes[l].begin());

  // Then iterated conditional modes: each link in turn takes the candidate that closes most loops.
  for (int round = 0; round < 20; ++round) {
    bool changed = false;
    for (std::size_t l = 0; l < links.size(); ++l) {
      if (links[l].transforms.size() < 2) continue;
      int best = chosen[l], best_closed = closed_count(l, chosen[l]);
      for (int c = 0; c < static_cast<int>(links[l].transforms.size()); ++c) {
        const int closed = closed_count(l, c);
        if (closed > best_closed) best = c, best_closed = closed;
      }
      if (best != chosen[l]) chosen[l] = best, changed = true;
    }
    if (!changed) break;
  }

  // The loops of every link with the final choice; links confirmed in one round vouch in the next.
  LoopSelectionResult out;
  for (bool growing = true; growing;) {
    out.links.assign(links.size(), {});
    for (std::size_t l = 0; l < links.size(); ++l) {
      LinkSelection& s = out.links[l];
      Picks picks;
      for (std::size_t t : through[l]) {
        if (!picks_with(triangles[t], l, chosen[l], picks)) continue;
        const auto [r, tol] = loop_residual(triangles[t], picks);
        ++s.loops;
        if (r <= tol && vouches(triangles[t], picks, l)) ++s.loops_closed;
        s.loop_residual_m = s.loop_residual_m < 0 ? r : std::min(s.loop_residual_m, r);
      }
    }
    growing = false;
    for (std::size_t l = 0; l < links.size(); ++l)
      if (out.links[l].loops_closed > 0 && !trusted[l]) trusted[l] = growing = true;
  }
  // An open loop has at least one wrong link. It blames an unconfirmed link of it unless a doubtful link
  // (ambiguous pairwise, confirmed by no loop) explains it: one whose partner is confirmed or doubtful too.
  // Where a doubtful link's partner is only unambiguous, nothing says which of the three is wrong, so the
  // loop blames both others as well (a scan that overlaps nothing must not ride in on a confident guess).
  // A link blamed by no open loop is consistent where all its loops close, else stands on its pairwise
  // verdict.
  auto confirmed = [&](std::size_t m) { return out.links[m].loops_closed > 0; };
  auto doubtful = [&](std::size_t m) { return !confirmed(m) && (chosen[m] < 0 || links[m].ambiguous); };
  for (std::size_t l = 0; l < links.size(); ++l) {
    LinkSelection& s = out.links[l];
    if (chosen[l] < 0) continue;  // kFailed
    Picks picks;
    bool open = false, blamed = false;
    for (std::size_t t : through[l]) {
      if (!picks_with(triangles[t], l, chosen[l], picks)) continue;
      const auto [r, tol] = loop_residual(triangles[t], picks);
      if (r <= tol) continue;
      open = true;
      std::array<std::size_t, 2> other;
      std::copy_if(triangles[t].link.begin(), triangles[t].link.end(), other.begin(), [&](std::size_t m) { return m != l; });
      const auto [a, b] = other;
      const bool explained = (doubtful(a) && (doubtful(b) || confirmed(b))) || (doubtful(b) && (doubtful(a) || confirmed(a)));
      blamed = blamed || !explained;
    }
    if (s.loops_closed > 0)
      s.verdict = LinkVerdict::kConfirmed;
    else if (blamed)
      s.verdict = LinkVerdict::kContradicted;
    else if (s.loops > 0 && !open)
      s.verdict = LinkVerdict::kConsistent;
    else
      s.verdict = links[l].ambiguous ? LinkVerdict::kUnresolved : LinkVerdict::kUnchecked;
    s.candidate = s.accepted() ? chosen[l] : -1;
  }
  for (const Triangle& tri : triangles) {
    Picks picks;
    if (!picks_with(tri, links.size(), 0, picks)) continue;
    const auto [r, tol] = loop_residual(tri, picks);
    ++out.loops_checked;
    out.loops_inconsistent += r > tol;
  }
  return out;
}

}  // namespace k4reg
