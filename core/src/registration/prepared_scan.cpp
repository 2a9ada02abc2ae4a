#include "k4reg/registration/prepared_scan.h"

#include "k4reg/geometry/neighbor_grid.h"
#include "k4reg/registration/pose_score.h"
#include "k4reg/registration/scanner_sampling.h"
#include "k4reg/registration/single_view.h"
#include "k4reg/util/error.h"
#include "k4reg/util/held_bytes.h"

#include <atomic>
#include <map>
#include <mutex>
#include <tuple>

namespace k4reg {
namespace {

// The heap bytes an entry's value holds beyond sizeof itself. Read while other entries are being made: a value
// is never changed once made (a pyramid's target search updates Pyramid::bytes instead).
std::size_t bytes_of(const IcpPyramid& pyramid) {
  std::size_t total = held_bytes(pyramid.stages);
  for (const IcpPyramid::Stage& stage : pyramid.stages)
    total += held_bytes(stage.points) + held_bytes(stage.normals) +
             (stage.grid ? sizeof(NeighborGrid) + stage.grid->bytes() : 0);
  return total;
}

struct Pyramid {
  explicit Pyramid(IcpPyramid made) : pyramid(std::move(made)), bytes(bytes_of(pyramid)) {}
  IcpPyramid pyramid;
  std::once_flag target_search;  // the grids and normals, added when the scan first serves as a target
  // bytes_of(pyramid), kept apart: the target search may be adding to the pyramid while bytes() is asked.
  std::atomic<std::size_t> bytes;
};

std::size_t bytes_of(const Pyramid& entry) { return entry.bytes.load(std::memory_order_relaxed); }
std::size_t bytes_of(const VoxelizedCloud& voxels) {
  return held_bytes(voxels.cloud.points) + held_bytes(voxels.cloud.intensity) + held_bytes(voxels.counts);
}
std::size_t bytes_of(const ScanKeypoints& keypoints) {
  return keypoints.signal.capacity() + held_bytes(keypoints.points) + held_bytes(keypoints.labels);
}
std::size_t bytes_of(const ScannerPosition& position) { return position.reason.capacity(); }
std::size_t bytes_of(const NeighbourAngles& angles) { return angles.bytes(); }
std::size_t bytes_of(const FreeSpaceImage& image) { return image.bytes(); }
// Nothing on the heap.
std::size_t bytes_of(const Sampling&) { return 0; }
std::size_t bytes_of(const std::optional<Eigen::Vector3f>&) { return 0; }
std::size_t bytes_of(double) { return 0; }

// Values by key, each made once from what `make` returns (std::call_once: a maker that throws leaves the entry
// to the next caller).
template <typename Key, typename Value>
class Entries {
 public:
  // The value made for key, or null where none has been made (yet).
  const Value* made(const Key& key) {
    const std::lock_guard lock(mutex_);
    const auto found = entries_.find(key);
    return found == entries_.end() || !found->second->ready.load(std::memory_order_acquire) ? nullptr
                                                                                            : found->second->value.get();
  }

  template <typename Make>
  Value& get(const Key& key, const Make& make) {
    Entry* entry;
    {
      const std::lock_guard lock(mutex_);
      std::unique_ptr<Entry>& slot = entries_[key];
      if (!slot) slot = std::make_unique<Entry>();
      entry = slot.get();
    }
    std::call_once(entry->once, [&] {
      entry->value = std::make_unique<Value>(make());
      entry->ready.store(true, std::memory_order_release);
    });
    return *entry->value;
  }

  // What the entries hold: each entry, its value and what that holds on the heap (values being made: the entry).
  std::size_t bytes() {
    const std::lock_guard lock(mutex_);
    std::size_t total = 0;
    for (const auto& [key, entry] : entries_) {
      total += sizeof(Key) + sizeof(Entry) + kNodeBytes;
      if (entry->ready.load(std::memory_order_acquire)) total += sizeof(Value) + bytes_of(*entry->value);
    }
    return total;
  }

 private:
  struct Entry {
    std::once_flag once;
    std::unique_ptr<Value> value;
    std::atomic<bool> ready{false};  // value made (made() reads it without the once_flag)
  };
  static constexpr std::size_t kNodeBytes = 32;  // a std::map node's links and colour
  std::mutex mutex_;
  std::map<Key, std::unique_ptr<Entry>> entries_;
};

}  // namespace

struct PreparedScan::Cache {
  Entries<int, Sampling> sampling;
  Entries<double, VoxelizedCloud> voxels;
  Entries<std::tuple<double, int, double>, Pyramid> pyramids;  // sigma, stages, distance factor
  Entries<std::tuple<double, int, bool, int, int, double>, ScanKeypoints> keypoints;  // sigma, signal, DoG
  Entries<int, NeighbourAngles> neighbour_angles;
  Entries<int, ScannerPosition> scanner, declared_scanner;
  Entries<double, FreeSpaceImage> free_space;
  Entries<double, std::optional<Eigen::Vector3f>> view_direction;       // sigma
  Entries<std::pair<double, double>, FreeSpaceImage> view_free_space;  // sigma, margin
  Entries<double, double> self_agreement;
};

PreparedScan::PreparedScan(const PointCloud& cloud) : cloud_(&cloud), cache_(std::make_unique<Cache>()) {}
PreparedScan::PreparedScan(PreparedScan&&) noexcept = default;

std::size_t PreparedScan::bytes() const {
  Cache& c = *cache_;
  return sizeof(Cache) + c.sampling.bytes() + c.voxels.bytes() + c.pyramids.bytes() + c.keypoints.bytes() +
         c.neighbour_angles.bytes() + c.scanner.bytes() + c.declared_scanner.bytes() + c.free_space.bytes() +
         c.view_direction.bytes() + c.view_free_space.bytes() + c.self_agreement.bytes();
}
PreparedScan::~PreparedScan() = default;

const Sampling& PreparedScan::sampling() const {
  return cache_->sampling.get(0, [&] { return measure_sampling(*cloud_); });
}

const VoxelizedCloud& PreparedScan::voxels(double sigma_m, const CancellationToken* cancel) const {
  return cache_->voxels.get(sigma_m, [&] { return voxel_grid(*cloud_, sigma_m, cancel); });
}

const IcpPyramid& PreparedScan::pyramid(double sigma_m, const IcpParams& params, PyramidRole role,
                                        const CancellationToken* cancel) const {
  IcpParams at_sigma = params;
  at_sigma.voxel_m = sigma_m;
  Pyramid& entry = cache_->pyramids.get({sigma_m, params.stages, params.max_distance_factor}, [&] {
    return make_icp_pyramid(voxels(sigma_m, cancel).cloud.points, at_sigma, PyramidRole::kSource, cancel);
  });
  if (role == PyramidRole::kTarget)
    std::call_once(entry.target_search, [&] {
      add_target_search(entry.pyramid, at_sigma, cancel);
      entry.bytes.store(bytes_of(entry.pyramid), std::memory_order_relaxed);
    });
  return entry.pyramid;
}

const ScanKeypoints& PreparedScan::keypoints(double sigma_m, KeypointSignal signal, bool use_intensity,
                                             const DogParams& dog, const CancellationToken* cancel) const {
  const std::tuple key{sigma_m, static_cast<int>(signal), use_intensity, dog.octaves, dog.scales_per_octave,
                       dog.min_contrast};
  return cache_->keypoints.get(key, [&] {
    const PointCloud& at_sigma = voxels(sigma_m, cancel).cloud;
    const SurfaceSignal surface = make_surface_signal(at_sigma, sigma_m, signal, use_intensity, cancel);
    DogKeypoints found = detect_dog_keypoints(at_sigma.points, surface.values, dog, cancel);
    ScanKeypoints out{surface.name, std::move(found.points), {}};
    for (const float response : found.response) out.labels.push_back(response > 0.0f);
    return out;
  });
}

namespace {
constexpr std::size_t kNeighbourPairs = 4096;  // enough to judge a position to a millimetre on simulated stations

// The scan's sampled neighbours, made once for both judgements of its scanner position.
const NeighbourAngles& neighbour_angles(Entries<int, NeighbourAngles>& entries, const PointCloud& cloud,
                                        double spacing_m, const CancellationToken* cancel) {
  return entries.get(0, [&] { return NeighbourAngles(cloud.points, spacing_m, kNeighbourPairs, cancel); });
}
}  // namespace

const ScannerPosition& PreparedScan::scanner(const CancellationToken* cancel) const {
  return cache_->scanner.get(0, [&] {
    // locate_scanner's first step is declared_scanner's: a confirmed declared position is taken as judged there.
    const ScannerPosition& declared = declared_scanner(cancel);
    if (declared.source != ScannerSource::kNone) return declared;
    return locate_scanner(*cloud_, neighbour_angles(cache_->neighbour_angles, *cloud_, sampling().spacing_m, cancel), cancel);
  });
}

const ScannerPosition& PreparedScan::declared_scanner(const CancellationToken* cancel) const {
  return cache_->declared_scanner.get(0, [&] {
    return check_declared_scanner(*cloud_, neighbour_angles(cache_->neighbour_angles, *cloud_, sampling().spacing_m, cancel));
  });
}

const ScannerPosition& PreparedScan::scanner_known(const CancellationToken* cancel) const {
  const ScannerPosition* located = cache_->scanner.made(0);
  return located ? *located : declared_scanner(cancel);
}

Eigen::Vector3f PreparedScan::scanner_local(const CancellationToken* cancel) const {
  return (scanner(cancel).position_m - cloud_->origin_m).cast<float>();
}

bool PreparedScan::scanner_surrounded(const CancellationToken* cancel) const {
  return could_surround_a_scanner(cloud_->points) && scanner(cancel).source != ScannerSource::kNone &&
         surrounded_by(cloud_->points, scanner_local(cancel));
}

const FreeSpaceImage& PreparedScan::free_space(double margin_m) const {
  return cache_->free_space.get(margin_m,
                                [&] { return FreeSpaceImage(cloud_->points, Viewpoint::at(scanner_local()), margin_m); });
}

const std::optional<Eigen::Vector3f>& PreparedScan::view_direction(double sigma_m, const CancellationToken* cancel) const {
  return cache_->view_direction.get(sigma_m, [&] {
    // The normals of at most 20 000 voxels are plenty for one direction and a share.
    constexpr std::size_t kJudgedPoints = 20000;
    const std::vector<Eigen::Vector3f>& points = voxels(sigma_m, cancel).cloud.points;
    const std::vector<Eigen::Vector3f> judged = every_kth(points, kJudgedPoints);
    const double radius_m = 2.0 * sigma_m;
    return single_view_direction(judged, estimate_normals(judged, points, NeighborGrid(points, radius_m), radius_m));
  });
}

const FreeSpaceImage& PreparedScan::view_free_space(double sigma_m, double margin_m, const CancellationToken* cancel) const {
  return cache_->view_free_space.get({sigma_m, margin_m}, [&] {
    const std::optional<Eigen::Vector3f>& toward = view_direction(sigma_m, cancel);
    if (!toward) fail(ErrorCode::kInternal, "view_free_space: the scan is not a single view");
    const double cell_m = std::max(sigma_m, 2.0 * sampling().spacing_m);
    return FreeSpaceImage(cloud_->points, Viewpoint::along(*toward), margin_m, cell_m);
  });
}

double PreparedScan::surface_self_agreement(double sigma_m, const CancellationToken* cancel) const {
  return cache_->self_agreement.get(sigma_m, [&] {
    PointCloud halves[2];
    for (std::size_t i = 0; i < cloud_->size(); ++i) halves[i % 2].points.push_back(cloud_->points[i]);
    IcpParams one_stage;
    one_stage.voxel_m = sigma_m;
    one_stage.stages = 1;
    const IcpPyramid surface =
        make_icp_pyramid(voxel_grid(halves[0], sigma_m, cancel).cloud.points, one_stage, PyramidRole::kTarget, cancel);
    const std::vector<Eigen::Vector3f> other = every_kth(voxel_grid(halves[1], sigma_m, cancel).cloud.points, 30000);
    return surface_agreement(other, Eigen::Matrix4d::Identity(), surface.stages.front());
  });
}

}  // namespace k4reg
