// Which pairs a large project registers: every pair's overlap estimated cheaply, then only each scan's best
// partners registered in full. The estimate is one small round of 4PCS on the two scans' keypoints (the ones
// their registration would start from, so they are computed once and reused): the share of the source's
// keypoints that the best of kScreenBases bases brings next to a target keypoint. Pairs that overlap share
// repeated keypoints; pairs that do not find none beyond chance. Its three best poses are scored on the
// voxelised clouds: on a small or busy scene a keypoint often has a neighbour by chance, a surface does not.
// Cost: N(N-1)/2 estimates (one 4PCS round on keypoints and three poses scored: about 0.1 s at 1 M points on 2
// cores, with the scans' keypoints and pyramids, which the pairs reuse), then at most `partners` x N full
// registrations instead of N(N-1)/2 (24 scans, 4 partners: at most 96 of 276 pairs; 100 scans: at most 400 of
// 4950), and as many again at most for scans the first pairs leave in no closed loop.
#pragma once

#include <cstddef>
#include <vector>

#include "k4reg/project/candidate_pairs.h"
#include "k4reg/registration/prepared_scan.h"
#include "k4reg/registration/registration.h"
#include "k4reg/util/cancellation.h"

namespace k4reg {

// Bases of the screening round, and the overlap that sets their width (the first round of the automatic
// overlap uses the same: pairs that overlap well, which are the ones worth registering, show up in it).
constexpr int kScreenBases = 48;
constexpr double kScreenOverlap = 0.8;
constexpr int kScreenPoses = 3;  // the distinct best poses scored on the clouds

// The overlap estimate of every pair (i < j, in the order of candidate_pairs(kAll)), in [0, 1]; 0 where 4PCS
// finds no pose or a scan has too few keypoints. At params' scale (or the automatic start), seed and signal.
// Deterministic at any thread count; throws kCancelled / kDeadlineExceeded when stopped.
std::vector<double> estimate_overlaps(const std::vector<PreparedScan>& scans, const RegistrationParams& params,
                                      const CancellationToken* cancel = nullptr, const ProgressCallback& progress = {});

// The pairs to register: for each scan its `partners` best-estimated partners (ties to the lower index), and
// then the best-estimated pairs that join what is still apart (a maximum spanning forest over the estimates),
// so that every scan is in a pair and the pairs connect all scans. Each pair once (low index first), sorted.
// `estimates` as estimate_overlaps returns them.
std::vector<ScanPair> best_partners(std::size_t scans, const std::vector<double>& estimates, std::size_t partners);

// For each scan in `extend`: its next `partners` best-estimated partners that `chosen` does not pair it with yet.
// For scans whose first partners left them in no closed loop (pair_stage.cpp registers these too, once).
// Each pair once (low index first), sorted; none already in `chosen`.
std::vector<ScanPair> more_partners(std::size_t scans, const std::vector<double>& estimates,
                                    const std::vector<ScanPair>& chosen, const std::vector<std::size_t>& extend,
                                    std::size_t partners);

}  // namespace k4reg
