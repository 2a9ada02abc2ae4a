// What a pairwise registration takes (register_clouds, registration.h): the two parameters that matter, the
// detector's, the coarse method's and the run's; defaults as stated.
#pragma once

#include <cstdint>

namespace k4reg {

enum class CoarseMethod {
  kKeypoint4pcs,  // K-4PCS: 4PCS on DoG keypoints (the paper's method)
  kPlain4pcs,     // baseline: 4PCS on a coarser voxel grid (the paper's Sec. 3.1)
};

enum class KeypointSignal {
  kAuto,        // intensity when both clouds have it (geometric too if its pose is weak), else geometric
  kIntensity,   // DoG of the (voxel-averaged) intensity
  kGeometric,   // DoG of the surface variation from local PCA (clouds without intensity)
};

enum class FreeSpaceCheck {
  kAuto,  // on when both scans have a terrestrial scanner position (scanner_position.h: from the file, the frame's
          // origin or the scan's sampling), or are single views of an object by a range camera (single_view.h: seen
          // along their viewing direction)
  kOn,    // from the scanner positions known, else the frames' origins
  kOff,
};

struct RegistrationParams {
  // The two parameters that matter (paper Tab. 1); 0 = found from the data (the default).
  // min_scale_m: minimum DoG scale sigma, also the voxel grid spacing. Automatic: the scans' robust
  // diameter / 128 (at least twice their point spacing). Given or not, a scale that yields too few
  // keypoints or no well-supported pose is halved, down to the point spacing (at most 4 scales).
  double min_scale_m = 0.0;
  // overlap: approximate overlap of the two scans, (0, 1]; it sets the number and width of the 4PCS
  // bases. Automatic: rounds of fresh bases for an overlap of 0.8, 0.6, then 0.4, until a pose is well
  // supported.
  double overlap = 0.0;

  // DoG detector (paper Tab. 1 defaults).
  int octaves = 5;
  int scales_per_octave = 5;
  double min_contrast = 0.01;  // fraction of the signal's range
  KeypointSignal signal = KeypointSignal::kAuto;

  // 4PCS.
  CoarseMethod method = CoarseMethod::kKeypoint4pcs;
  double plain_voxel_m = 0.0;  // voxel spacing for kPlain4pcs; 0 = chosen to give ~ as many points as keypoints
  int max_bases = 0;           // number of 4-point bases L; 0 = from the overlap
  int hypotheses_kept = 5;     // distinct hypotheses re-scored by the symmetry guard
  // Penalise hypotheses that put source points where the target scanner (at the target file's origin)
  // saw empty space: breaks the 180-degree flips of symmetric rooms.
  FreeSpaceCheck free_space = FreeSpaceCheck::kAuto;

  // Levelled scanners (a tilt compensator makes their z axes vertical): only rotations about z are searched and
  // refined, so no out-of-plane flip can win, and fewer 4PCS sets pass the fit. Every transform is then a
  // rotation about z and a translation. Wrong for tilted scans (a handheld or mobile scanner).
  bool levelled = false;

  // Where a scale finds no well-supported pose, search the pair again with the scans swapped (4PCS draws its
  // bases in the source) and keep a pose found there if it is well supported from the source's side too.
  // A project turns it off for its pairs: its loops confirm a link found from either side, and it searches
  // the pairs of scans no loop confirms from the other side itself.
  bool search_other_side = true;

  // ICP refinement.
  bool icp = true;
  int icp_max_iterations = 50;

  std::uint64_t seed = 42;
  int threads = 0;             // 0 = all cores
  double time_budget_s = 0.0;  // 0 = unlimited; otherwise kDeadlineExceeded after this long (at most 1e9)
};

}  // namespace k4reg
