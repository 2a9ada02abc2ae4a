#include "k4reg/registration/fine_polish.h"

#include <algorithm>
#include <cmath>

namespace k4reg {

double fine_polish_spacing_m(double sigma_m, std::size_t points_at_sigma, std::size_t scan_points,
                             double sampling_spacing_m) {
  const double affordable_m =
      scan_points <= kFinePolishMaxPoints ? 0.0
                                          : sigma_m * std::sqrt(static_cast<double>(points_at_sigma) / kFinePolishMaxPoints);
  const double spacing_m = std::max({sigma_m / 4.0, sampling_spacing_m / 2.0, affordable_m});
  return spacing_m <= sigma_m / 2.0 ? spacing_m : 0.0;
}

IcpResult polish_winner(const PreparedScan& source, const PreparedScan& target, const IcpPyramid& source_at_sigma,
                        const IcpPyramid& target_at_sigma, double sigma_m, const Eigen::Matrix4d& pose,
                        const IcpParams& params, const CancellationToken* cancel) {
  IcpParams at_sigma = params;
  at_sigma.finest_stage_only = true;
  const IcpResult polished = refine_icp(source_at_sigma, target_at_sigma, pose, at_sigma, cancel);
  // The sampling (a few tens of milliseconds on a large scan) is measured only where the grid's size allows
  // a finer stage at all.
  auto fine_m = [&](const PreparedScan& scan) {
    const std::size_t points_at_sigma = scan.voxels(sigma_m, cancel).cloud.size();
    if (fine_polish_spacing_m(sigma_m, points_at_sigma, scan.cloud().size(), 0.0) == 0.0) return 0.0;
    return fine_polish_spacing_m(sigma_m, points_at_sigma, scan.cloud().size(), scan.sampling().spacing_m);
  };
  if (params.max_iterations == 0) return polished;
  const double source_m = fine_m(source);
  const double target_m = source_m > 0.0 ? fine_m(target) : 0.0;
  if (source_m == 0.0 || target_m == 0.0) return polished;
  IcpParams fine = params;
  fine.stages = 1;
  fine.converged_step_voxels = params.converged_step_voxels * sigma_m / target_m;
  fine.measure_fit = false;  // the figures come from sigma's stage below
  const IcpResult finer =
      refine_icp(thin_pyramid(source.pyramid(source_m, fine, PyramidRole::kSource, cancel), kFinePolishSourcePoints),
                 target.pyramid(target_m, fine, PyramidRole::kTarget, cancel), polished.transform, fine, cancel);
  // The figures at sigma's stage, for the finer pose (no iterations: the final accumulation only).
  at_sigma.max_iterations = 0;
  IcpResult out = refine_icp(source_at_sigma, target_at_sigma, finer.transform, at_sigma, cancel);
  out.converged = polished.converged && finer.converged;
  out.iterations = polished.iterations + finer.iterations;
  return out;
}

}  // namespace k4reg
