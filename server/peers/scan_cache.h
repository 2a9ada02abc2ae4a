// The scans coordinating replicas sent this replica for their pair jobs (RegisterPair), kept by digest together
// with the work done on them (PreparedScan: voxels, pyramids, keypoints). The next pairs of the same scans need
// only their digests, and skip that work: a scan of an all-pairs project is in up to N - 1 pairs. The budget
// bounds the bytes really held: a scan's points and intensities (capacity) plus PreparedScan::bytes(), which
// grows as pairs prepare new scales. A scan is counted when it comes in and again whenever a pair takes it
// (find) or gives it back (release); the least recently used scans that no pair holds then leave until the
// cache is within budget. Scans pairs hold stay (and stay counted) until released. Thread-safe; pairs running
// at once share a scan.
#pragma once

#include <cstddef>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "k4reg/geometry/point_cloud.h"
#include "k4reg/registration/prepared_scan.h"

namespace k4reg::service {

class ScanCache {
 public:
  struct Scan {
    explicit Scan(PointCloud points) : cloud(std::move(points)), prepared(cloud) {}
    std::size_t bytes() const;  // the cloud's and its preparation's
    PointCloud cloud;
    PreparedScan prepared;  // refers to `cloud`: a Scan never moves (always held by shared_ptr)
  };

  explicit ScanCache(std::size_t budget_bytes) : budget_(budget_bytes) {}
  // Null when not held.
  std::shared_ptr<const Scan> find(const std::string& digest);
  // The scan held under `digest`: `cloud` if it was not held yet (kept only if it alone fits the budget).
  std::shared_ptr<const Scan> insert(const std::string& digest, PointCloud cloud);
  // A pair is done with `scan` (from find or insert; null is ignored): drops that reference, counts what the pair
  // added to its preparation, and lets unused scans leave while over budget.
  void release(std::shared_ptr<const Scan> scan);
  std::size_t bytes() const;

 private:
  struct Held {
    std::string digest;
    std::shared_ptr<const Scan> scan;
    std::size_t bytes;
  };
  // Re-measures `held` (under mutex_).
  void recount(Held& held);
  // Moves the least recently used scans no pair holds into `leaving` until within budget (under mutex_; they are
  // freed by the caller after unlocking).
  void evict(std::vector<std::shared_ptr<const Scan>>& leaving);

  const std::size_t budget_;
  mutable std::mutex mutex_;
  std::list<Held> recent_;  // most recently used first
  std::map<std::string, std::list<Held>::iterator> by_digest_;
  std::size_t bytes_ = 0;
};

}  // namespace k4reg::service
