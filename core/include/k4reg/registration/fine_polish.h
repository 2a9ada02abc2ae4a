// The winner's last polish, below the minimum scale where that is cheap. ICP runs on centroid voxel grids, and
// on a curved surface a cell's centroid lies off the surface towards its concave side by an amount that depends
// on where the cell boundaries fall, which differs between two scans' grids: on the Stanford bunny at
// sigma = 2 mm that left project scans 0.5-1.6 mm off the truth. A polish on grids four times finer cuts it to
// 0.34-0.6 mm. TLS scenes (planes, sigma of centimetres) hardly see the bias and have millions of points at such
// spacings, so the extra stage is kept to small grids.
// Cost: per scan, one voxel grid, normals and neighbour grid at that spacing (at most about kFinePolishMaxPoints
// points); per pair, one ICP stage on kFinePolishSourcePoints source points (on the bunny's ten scans, 45 pairs:
// +12 % for the project; on all of its points the same poses to 0.02 mm, at +30 %).
#pragma once

#include <Eigen/Core>
#include <cstddef>

#include "k4reg/registration/icp.h"
#include "k4reg/registration/prepared_scan.h"
#include "k4reg/util/cancellation.h"

namespace k4reg {

constexpr std::size_t kFinePolishMaxPoints = 50000;
constexpr std::size_t kFinePolishSourcePoints = 10000;

// One scan's spacing for the extra stage: sigma / 4, no finer than half the scan's sampling spacing (the grid
// then holds every point, and ICP's correspondences, within 2.5 cells, still reach the neighbouring points),
// and for a scan of more than kFinePolishMaxPoints points coarse enough that its grid holds about that many
// (estimated from its grid at sigma: a surface's cells grow as 1 / spacing^2). 0 (no extra stage) where that
// spacing would be coarser than sigma / 2.
double fine_polish_spacing_m(double sigma_m, std::size_t points_at_sigma, std::size_t scan_points,
                             double sampling_spacing_m);

// The winner polished on every source point at sigma's stage (params: the finest stage of the pyramids at sigma),
// then at each scan's fine spacing where both have one, converging to the same step in metres. The quality
// figures (rmse, overlap, inliers, information, converged) are those at sigma's stage for the final pose, so
// that they compare with every other pair's; iterations count both stages.
IcpResult polish_winner(const PreparedScan& source, const PreparedScan& target, const IcpPyramid& source_at_sigma,
                        const IcpPyramid& target_at_sigma, double sigma_m, const Eigen::Matrix4d& pose,
                        const IcpParams& params, const CancellationToken* cancel = nullptr);

}  // namespace k4reg
