#include "k4reg/registration/symmetry_guard.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>

#include "k4reg/registration/ambiguity_margin.h"
#include "k4reg/registration/four_pcs.h"
#include "k4reg/registration/icp.h"
#include "k4reg/geometry/neighbor_grid.h"
#include "k4reg/geometry/normal_space_sampling.h"
#include "k4reg/geometry/rigid_fit.h"
#include "k4reg/geometry/rigid_motion.h"
#include "k4reg/registration/translation_vote.h"

namespace k4reg {
namespace {

// Whether two scanners looked at a surface (normal n, unoriented) from the same side: a pose that
// matches a surface's front in one scan to its back in the other is wrong (turned upside down, the
// ground near one scanner fits the ground near the other while everything above it goes underground).
// Grazing views cannot tell the sides apart.
bool seen_from_the_same_side(const Eigen::Vector3f& n, const Eigen::Vector3f& view_a, const Eigen::Vector3f& view_b) {
  constexpr float kGrazingCos = 0.1f;
  const float a = n.dot(view_a), b = n.dot(view_b);
  return a * b >= 0.0f || std::abs(a) < kGrazingCos * view_a.norm() || std::abs(b) < kGrazingCos * view_b.norm();
}

// Centre of the middle 90 % of the points per axis: a room scan's stray points through windows and
// doors must not pull it, and unlike the centroid it does not follow the scanner's dense near field.
Eigen::Vector3f trimmed_centre(const std::vector<Eigen::Vector3f>& points) {
  Eigen::Vector3f centre;
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<float> values(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) values[i] = points[i](axis);
    const std::size_t low = values.size() / 20, high = values.size() - 1 - values.size() / 20;
    std::nth_element(values.begin(), values.begin() + low, values.end());
    const float a = values[low];
    std::nth_element(values.begin(), values.begin() + high, values.end());
    centre(axis) = 0.5f * (a + values[high]);
  }
  return centre;
}

// The principal axes of the points about their centre, and of the normals (the eigenvectors of
// sum n n^T): a rectangular room's or a plaza's main surfaces lie along the second set whatever the
// scan's extent, while the first tilts by degrees where the ground reaches further on one side.
Eigen::Matrix3d point_axes(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3d& centre) {
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3f& p : points) cov += (p.cast<double>() - centre) * (p.cast<double>() - centre).transpose();
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors();
}

Eigen::Matrix3d normal_axes(const std::vector<Eigen::Vector3f>& normals) {
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3f& n : normals) scatter += n.cast<double>() * n.cast<double>().transpose();
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors();
}

// Half-turns about the columns of `axes` through `centre`: a rectangular room's shell looks the same
// after a half turn about the vertical (and nearly so about the other two axes), so a pose composed with
// one of them is where 4PCS's symmetric twin of the true pose lies. As target -> target maps.
std::vector<Eigen::Matrix4d> half_turns(const Eigen::Matrix3Xd& axes, const Eigen::Vector3d& centre) {
  std::vector<Eigen::Matrix4d> turns;
  for (Eigen::Index axis = 0; axis < axes.cols(); ++axis) {
    const Eigen::Matrix3d r = Eigen::AngleAxisd(M_PI, axes.col(axis).normalized()).toRotationMatrix();
    Eigen::Matrix4d s = Eigen::Matrix4d::Identity();
    s.topLeftCorner<3, 3>() = r;
    s.topRightCorner<3, 1>() = centre - r * centre;
    turns.push_back(s);
  }
  return turns;
}

}  // namespace

ScoredSource scored_source(const IcpPyramid::Stage& stage, std::size_t max_points) {
  ScoredSource scored;
  scored.points = every_kth(stage.points, max_points);
  // Only the rough incidence is asked of these normals: a voxel's nearest neighbours (about 8 on a plane) will do.
  const double radius_m = 1.5 * stage.voxel_m;
  scored.normals = estimate_normals(scored.points, stage.points, NeighborGrid(stage.points, radius_m), radius_m);
  return scored;
}

// Without views: the share of source points with a target point within tau. With the target's free
// space, a point is also consistent where it lies at the target scanner's first return in its
// direction (sparse far surfaces have gaps wider than tau), contradicted where the target scanner saw
// through it or saw open sky around it (where its surface would have faced that scanner), and no
// evidence either way where that scanner could not see it (behind its first return, or no return) or
// where the two scanners saw its surface from opposite sides. Counting unseen points
// as misses favours the pose that maps one scanner's occlusion shadows onto the other's — in a
// symmetric room, the flip. So the score is, of the points with evidence, the share consistent less
// the share contradicted. A point whose surface the target scanner would meet at grazing incidence is no
// evidence either: scanners return little or nothing there (along a corridor's far walls, say), so their
// free space reaches past such surfaces.
double cloud_score(const ScoredSource& scored, const IcpPyramid::Stage& reference, const NeighborGrid& grid,
                   float tau, const Eigen::Matrix4d& t, const ScanViews* views, double overlap) {
  constexpr float kVisibleCos = 0.1f;  // incidence within about 84 degrees of the surface normal
  // Open sky contradicts only a surface that would have faced the scanner (within 60 degrees): obliquely
  // seen facade tops and dark surfaces far away return nothing, and a true pose puts points there.
  constexpr float kFacingCos = 0.5f;
  const std::vector<Eigen::Vector3f>& source = scored.points;
  const Eigen::Affine3f a = to_affine3f(t);
  const Viewpoint source_view = views ? views->source.moved(a) : Viewpoint{};
  struct Counts {
    std::size_t consistent = 0, contradicted = 0, unseen = 0;
  };
  // Integer counts: the same for any split over threads.
  const Counts counts = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, source.size(), 4096), Counts{},
      [&](const tbb::blocked_range<std::size_t>& range, Counts c) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
          const Eigen::Vector3f q = a * source[i];
          const int k = grid.nearest_within(q, tau);
          if (k >= 0) {
            const bool same_side = !views || seen_from_the_same_side(reference.normals[k], source_view.ray_to(q),
                                                                      views->target.ray_to(reference.points[k]));
            ++(same_side ? c.consistent : c.unseen);
            continue;
          }
          if (!views) continue;
          const FreeSpaceImage::Seen seen = views->target_free_space->classify(q);
          switch (seen) {
            case FreeSpaceImage::Seen::kSurface: ++c.consistent; break;
            case FreeSpaceImage::Seen::kEmpty:
            case FreeSpaceImage::Seen::kOpen: {
              const Eigen::Vector3f ray = views->target.ray_to(q);
              const float cos_needed = seen == FreeSpaceImage::Seen::kOpen ? kFacingCos : kVisibleCos;
              const bool visible = std::abs((a.linear() * scored.normals[i]).dot(ray)) >= cos_needed * ray.norm();
              ++(visible ? c.contradicted : c.unseen);
              break;
            }
            case FreeSpaceImage::Seen::kOccluded:
            case FreeSpaceImage::Seen::kUnknown: ++c.unseen; break;
          }
        }
        return c;
      },
      [](Counts x, const Counts& y) {
        return Counts{x.consistent + y.consistent, x.contradicted + y.contradicted, x.unseen + y.unseen};
      });
  const std::size_t consistent = counts.consistent, contradicted = counts.contradicted, unseen = counts.unseen;
  // A pose that puts most points out of the target scanner's sight (behind its walls, say) has little
  // evidence, and the few points left can all agree: the share is taken of at least half the overlap
  // the caller expects, so such a pose cannot outscore one that the target sees well.
  const double evidence = std::max(static_cast<double>(source.size() - unseen), 0.5 * overlap * source.size());
  return (static_cast<double>(consistent) - static_cast<double>(contradicted)) / std::max(1.0, evidence);
}

SymmetryGuardResult rank_hypotheses(const IcpPyramid& source, const IcpPyramid& target,
                                    std::vector<Hypothesis> hypotheses, const RankingOptions& options,
                                    const ScanViews* views, const CancellationToken* cancel) {
  constexpr int kStages = 2, kIterations = 6;  // settle, don't polish: the final ICP does that
  // A pose settles on a few thousand points and is scored on ten thousand (a share to within ~0.5 %: the
  // contenders are scored again on up to 30 000 once refined).
  constexpr std::size_t kSettlePoints = 4000, kScoredPoints = 10000;
  const IcpPyramid settling_source = thin_pyramid(source, kSettlePoints);
  const ScoredSource scored = scored_source(source.stages.at(kStages - 1), kScoredPoints);
  const auto& reference = target.stages.at(kStages - 1);
  const double voxel_m = reference.voxel_m;
  const float tau = static_cast<float>(1.5 * voxel_m);
  const Eigen::Vector3d source_centre = centroid(source.stages.front().points);  // where poses are compared
  const NeighborGrid grid(reference.points, 2.0 * tau);  // 8-cell look-ups for the score
  IcpParams quick;
  quick.stages = kStages;
  quick.max_iterations = kIterations;
  quick.levelled = options.levelled;
  quick.converged_step_voxels = kSettledStepVoxels;
  quick.measure_fit = false;  // settling needs the pose only: the score follows
  // A hypothesis can be a metre or two off where it matters, beyond the guard's ICP stages: a 4PCS fit on
  // keypoints a few metres apart tilts a wide outdoor scene by degrees, and a twin's estimated centre is
  // rough. Two wider stages (2 and 4 times the pyramid's coarsest spacing, a few thousand points) reach
  // further, but in a room they can also slide an exact pose along a wall; so each hypothesis settles
  // from where it is and, if the wide stages take it elsewhere, from there too: the better score stands.
  IcpParams wide;
  wide.voxel_m = 2.0 * source.stages.front().voxel_m;
  wide.stages = 2;
  wide.max_iterations = 10;
  wide.levelled = options.levelled;
  wide.converged_step_voxels = kSettledStepVoxels;
  wide.measure_fit = false;
  const IcpPyramid wide_source =
      thin_pyramid(make_icp_pyramid(source.stages.front().points, wide, PyramidRole::kSource, cancel), kSettlePoints);
  const IcpPyramid wide_target = make_icp_pyramid(target.stages.front().points, wide, PyramidRole::kTarget, cancel);
  auto settle = [&](Hypothesis& h, bool from_afar) {
    const Eigen::Matrix4d start = h.transform;
    h.transform = refine_icp(settling_source, target, start, quick, cancel).transform;
    h.cloud_score = cloud_score(scored, reference, grid, tau, h.transform, views, options.overlap);
    if (!from_afar) return;
    const Eigen::Matrix4d pulled = refine_icp(wide_source, wide_target, start, wide, cancel).transform;
    if (!distinct_transforms(pulled, h.transform, source_centre, 1.0, target.stages.front().voxel_m)) return;  // same basin
    const Eigen::Matrix4d settled = refine_icp(settling_source, target, pulled, quick, cancel).transform;
    const double score = cloud_score(scored, reference, grid, tau, settled, views, options.overlap);
    if (score > h.cloud_score) {
      h.transform = settled;
      h.cloud_score = score;
    }
  };
  auto by_score = [](const Hypothesis& a, const Hypothesis& b) { return a.cloud_score > b.cloud_score; };
  // Hypotheses settle independently (in parallel: a few thousand points each keep one core busy).
  // from_afar: also from where the wide stages pull it; a shifted copy lies within a vote cell of its place,
  // which the guard's own stages reach.
  auto settle_all = [&](std::vector<Hypothesis>& list, bool from_afar) {
    tbb::parallel_for(std::size_t{0}, list.size(), [&](std::size_t i) { settle(list[i], from_afar); });
  };
  // Hypotheses that a verdict has refined already (a periodic search) are only scored again.
  if (options.periodic)
    tbb::parallel_for(std::size_t{0}, hypotheses.size(), [&](std::size_t i) {
      hypotheses[i].cloud_score =
          cloud_score(scored, reference, grid, tau, hypotheses[i].transform, views, options.overlap);
    });
  else
    settle_all(hypotheses, true);
  std::stable_sort(hypotheses.begin(), hypotheses.end(), by_score);
  // 4PCS on a symmetric room often finds only the flipped pose; its symmetric twin must compete too.
  // Turned about the principal axes through the target's centre, or about the normals' axes and then
  // shifted to where the vote puts it: the symmetric structure need not stand at the centre of its scan.
  const auto& coarse_source = source.stages.front();
  const auto& coarse_target = target.stages.front();
  if (!hypotheses.empty() && coarse_target.points.size() >= 10) {
    constexpr std::size_t kVoters = 1500;
    const NeighborGrid source_grid(coarse_source.points, 2.5 * coarse_source.voxel_m);
    const std::vector<Eigen::Vector3f> voting_source = normal_space_sample(
        coarse_source.points, estimate_normals(coarse_source.points, source_grid, 2.5 * coarse_source.voxel_m), kVoters);
    const std::vector<Eigen::Vector3f> voting_target =
        normal_space_sample(coarse_target.points, coarse_target.normals, kVoters);
    const Eigen::Vector3d centre = trimmed_centre(coarse_target.points).cast<double>();
    auto twin = [](const Eigen::Matrix4d& transform) {
      Hypothesis h;
      h.transform = transform;
      return h;
    };
    // Levelled scans have one symmetry axis to try: the vertical.
    const auto axes = [&](const Eigen::Matrix3d& principal) {
      return options.levelled ? half_turns(Eigen::Vector3d::UnitZ(), centre) : half_turns(principal, centre);
    };
    const std::vector<Eigen::Matrix4d> principal_turns = axes(point_axes(coarse_target.points, centre));
    const std::vector<Eigen::Matrix4d> normal_turns = axes(normal_axes(coarse_target.normals));
    // Whether the best hypothesis beats the first distinct one by the margin a result needs.
    // The first hypothesis after the best that is a distinct pose.
    auto first_rival = [&] {
      return std::find_if(hypotheses.begin() + 1, hypotheses.end(), [&](const Hypothesis& h) {
        return distinct_transforms(hypotheses.front().transform, h.transform, source_centre, 2.0, 2.0 * voxel_m);
      });
    };
    auto decisive = [&] {
      const Hypothesis& best = hypotheses.front();
      const auto rival = first_rival();
      return rival == hypotheses.end() || best.cloud_score <= 0 ||
             (best.cloud_score - rival->cloud_score) / best.cloud_score >= kAmbiguousMargin;
    };
    // The best hypothesis gets its half-turn twins. If asked (periodic), a twin that wins gets its own, and
    // while no hypothesis stands out, the best also gets shifted copies: a periodic scene (a corridor's doors, a
    // facade's windows, racks) repeats under shifts too, and 4PCS tends to find the copy that puts one
    // scanner where the other stood (their dense near fields then meet). They are the vote's further peaks,
    // at the best's own rotation and at its half-turns.
    constexpr std::size_t kTwinShifts = 2, kPeriodicShifts = 12;
    constexpr int kPeriodicSeparationCells = 3;
    constexpr int kMaxRounds = 4;
    std::vector<Eigen::Matrix4d> twinned, shifted;  // the bests expanded so far, each way
    auto among = [&](const std::vector<Eigen::Matrix4d>& done, const Eigen::Matrix4d& t) {
      return std::any_of(done.begin(), done.end(),
                         [&](const Eigen::Matrix4d& d) { return !distinct_transforms(d, t, source_centre, 2.0, 2.0 * voxel_m); });
    };
    for (int round = 0; round < (options.periodic ? kMaxRounds : 1); ++round) {
      const Eigen::Matrix4d best = hypotheses.front().transform;
      const bool twins_only = !among(twinned, best);
      if (!twins_only && (!options.periodic || decisive() || among(shifted, best))) break;
      // With free space, a best that is not well supported may be a wrong pose that outscored a flip of the
      // truth: the runner-up's twins compete too.
      std::vector<Eigen::Matrix4d> expanded{best};
      if (twins_only && views && hypotheses.front().cloud_score < kWellSupportedWithFreeSpace) {
        const auto rival = first_rival();
        if (rival != hypotheses.end() && !among(twinned, rival->transform)) expanded.push_back(rival->transform);
      }
      std::vector<Hypothesis> twins;
      std::vector<Eigen::Matrix4d> turned;  // the rotations to vote at: target -> target maps composed with a pose
      for (const Eigen::Matrix4d& pose : expanded) {
        (twins_only ? twinned : shifted).push_back(pose);
        if (twins_only)
          for (const Eigen::Matrix4d& s : principal_turns) twins.push_back(twin(s * pose));
        else
          turned.push_back(pose);
        for (const Eigen::Matrix4d& s : normal_turns) turned.push_back(s * pose);
      }
      const std::size_t peaks = twins_only ? kTwinShifts : kPeriodicShifts;
      // One vote per rotation (1500 x 1500 pairs each), side by side.
      std::vector<std::vector<Eigen::Vector3d>> shifts(turned.size());
      tbb::parallel_for(std::size_t{0}, turned.size(), [&](std::size_t i) {
        shifts[i] = vote_translations(voting_source, voting_target, turned[i].topLeftCorner<3, 3>(),
                                      2.0 * coarse_target.voxel_m, peaks, twins_only ? 1 : kPeriodicSeparationCells);
      });
      for (std::size_t i = 0; i < turned.size(); ++i)
        for (const Eigen::Vector3d& shift : shifts[i]) {
          Eigen::Matrix4d moved = turned[i];
          moved.topRightCorner<3, 1>() = shift;
          twins.push_back(twin(moved));
        }
      settle_all(twins, twins_only);
      hypotheses.insert(hypotheses.end(), twins.begin(), twins.end());
      std::stable_sort(hypotheses.begin(), hypotheses.end(), by_score);
    }
  }
  SymmetryGuardResult result;
  // Hypotheses that ICP brought to the same pose are one hypothesis.
  for (const Hypothesis& h : hypotheses)
    if (std::all_of(result.hypotheses.begin(), result.hypotheses.end(), [&](const Hypothesis& d) {
          return distinct_transforms(d.transform, h.transform, source_centre, 2.0, 2.0 * voxel_m);
        }))
      result.hypotheses.push_back(h);
  const auto& ranked = result.hypotheses;
  if (ranked.size() >= 2 && ranked[0].cloud_score > 0)
    result.ambiguity_margin = std::clamp((ranked[0].cloud_score - ranked[1].cloud_score) / ranked[0].cloud_score, 0.0, 1.0);
  return result;
}

}  // namespace k4reg
