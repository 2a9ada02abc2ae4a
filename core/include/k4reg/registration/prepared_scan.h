// One scan and the work registration does on it alone: its sampling, and per scale its voxel grid, ICP pyramid,
// DoG keypoints and free-space image. Each is computed when first asked for and then kept, so a project computes
// them once per scan instead of once per pair (a scan is in up to N - 1 pairs); register_clouds on two plain
// clouds prepares them on the fly. An entry is exactly what register_clouds computes for the scan alone, so
// results do not depend on the sharing.
// Thread-safe: pairs running at once share the entries (the first to ask computes, the others wait; a cancelled
// computation leaves the entry to the next asker).
// Memory, per scale used: the voxel grid (16 B per voxel, 20 with intensity), the pyramid (its points, and for a
// target its neighbour grids and normals: about 60 B per voxel in all), the keypoints and the free-space image;
// bytes() counts what the entries made so far hold.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "k4reg/geometry/point_cloud.h"
#include "k4reg/geometry/sampling.h"
#include "k4reg/geometry/voxel_grid.h"
#include "k4reg/registration/dog_keypoints.h"
#include "k4reg/registration/free_space.h"
#include "k4reg/registration/icp.h"
#include "k4reg/registration/scanner_position.h"
#include "k4reg/registration/surface_signal.h"
#include "k4reg/util/cancellation.h"

namespace k4reg {

// A scan's DoG keypoints on one signal: the points 4PCS matches and their extremum labels (1 maximum, 0 minimum).
struct ScanKeypoints {
  std::string signal;  // the signal they came from: "intensity" or "geometric"
  std::vector<Eigen::Vector3f> points;
  std::vector<std::uint8_t> labels;
};

class PreparedScan {
 public:
  // Keeps a reference: the cloud must outlive this.
  explicit PreparedScan(const PointCloud& cloud);
  PreparedScan(PreparedScan&&) noexcept;
  ~PreparedScan();

  const PointCloud& cloud() const { return *cloud_; }
  // The heap bytes of the entries made so far (capacities; not the cloud, which is the caller's). Cheap: a walk
  // over the entries and their vectors, no point visited. Thread-safe, while other pairs add entries.
  std::size_t bytes() const;
  const Sampling& sampling() const;
  const VoxelizedCloud& voxels(double sigma_m, const CancellationToken* cancel) const;
  // At sigma_m's voxels, with params' stages; PyramidRole::kTarget adds the neighbour grids and normals.
  const IcpPyramid& pyramid(double sigma_m, const IcpParams& params, PyramidRole role,
                            const CancellationToken* cancel) const;
  // use_intensity: whether the pair uses intensity (both scans have it); see make_surface_signal.
  const ScanKeypoints& keypoints(double sigma_m, KeypointSignal signal, bool use_intensity, const DogParams& dog,
                                 const CancellationToken* cancel) const;
  // Where its scanner stood (locate_scanner, scanner_position.h): from the file, the frame's origin or the sampling.
  const ScannerPosition& scanner(const CancellationToken* cancel = nullptr) const;
  // Only whether the declared position (file or origin) is confirmed by the sampling, without searching elsewhere:
  // none otherwise. Cheap: the sampled neighbours and one judgement.
  const ScannerPosition& declared_scanner(const CancellationToken* cancel = nullptr) const;
  // scanner() where it has been asked for, else declared_scanner(): what is known without a search.
  const ScannerPosition& scanner_known(const CancellationToken* cancel = nullptr) const;
  // Whether scanner() is known and could be a terrestrial scanner's position (surrounded_by): what the scanner
  // free-space evidence needs.
  bool scanner_surrounded(const CancellationToken* cancel = nullptr) const;
  // scanner()'s position in the cloud's local frame (the frame's origin where none is known).
  Eigen::Vector3f scanner_local(const CancellationToken* cancel = nullptr) const;
  // The raw points seen from scanner_local(), with this margin.
  const FreeSpaceImage& free_space(double margin_m) const;
  // Where the scan is one range camera's view of an object (single_view.h, judged on normals at sigma_m's
  // voxels): the direction toward the camera; else nothing.
  const std::optional<Eigen::Vector3f>& view_direction(double sigma_m, const CancellationToken* cancel) const;
  // The raw points seen along view_direction(sigma_m) (which must be known), in a parallel image with cells of
  // sigma_m or twice the sampling spacing, whichever is larger, and this margin.
  const FreeSpaceImage& view_free_space(double sigma_m, double margin_m, const CancellationToken* cancel) const;
  // What a perfect registration onto this scan reaches in surface_agreement (pose_score.h) at sigma_m: the
  // voxel centroids of every other point against the surface of the rest, two samplings of one surface with
  // independent noise. Clean scans give 0.9 or more; noise and clutter at the scale of sigma_m give less.
  // Costs two voxel grids of half the points and one set of normals; computed once per scale.
  double surface_self_agreement(double sigma_m, const CancellationToken* cancel) const;

 private:
  struct Cache;  // the entries, each made once
  const PointCloud* cloud_;
  std::unique_ptr<Cache> cache_;
};

}  // namespace k4reg
