// The scans coordinating replicas sent this replica for their pair jobs (RegisterPair), kept by digest together
// with the work done on them (PreparedScan: voxels, pyramids, keypoints). The next pairs of the same scans need
// only their digests, and skip that work: a scan of an all-pairs project is in up to N - 1 pairs. The least
// recently used scans leave first once the cache holds more than its budget (kBytesPerPoint per point: the
// points and what preparing them adds). Thread-safe; pairs running at once share a scan.
#pragma once

#include <cstddef>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "k4reg/geometry/point_cloud.h"
#include "k4reg/registration/prepared_scan.h"

namespace k4reg::service {

class ScanCache {
 public:
  struct Scan {
    explicit Scan(PointCloud points) : cloud(std::move(points)), prepared(cloud) {}
    PointCloud cloud;
    PreparedScan prepared;  // refers to `cloud`: a Scan never moves (always held by shared_ptr)
  };

  explicit ScanCache(std::size_t budget_bytes) : budget_(budget_bytes) {}
  // Null when not held.
  std::shared_ptr<const Scan> find(const std::string& digest);
  // The scan held under `digest`: `cloud` if it was not held yet (then the least recently used others may leave).
  std::shared_ptr<const Scan> insert(const std::string& digest, PointCloud cloud);
  std::size_t bytes() const;

 private:
  struct Held {
    std::string digest;
    std::shared_ptr<const Scan> scan;
    std::size_t bytes;
  };
  const std::size_t budget_;
  mutable std::mutex mutex_;
  std::list<Held> recent_;  // most recently used first
  std::map<std::string, std::list<Held>::iterator> by_digest_;
  std::size_t bytes_ = 0;
};

}  // namespace k4reg::service
