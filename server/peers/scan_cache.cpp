#include "peers/scan_cache.h"

#include "k4reg/util/held_bytes.h"

namespace k4reg::service {

std::size_t ScanCache::Scan::bytes() const {
  return sizeof(Scan) + held_bytes(cloud.points) + held_bytes(cloud.intensity) + prepared.bytes();
}

std::shared_ptr<const ScanCache::Scan> ScanCache::find(const std::string& digest) {
  std::vector<std::shared_ptr<const Scan>> leaving;  // freed after unlocking (declared before the lock)
  const std::lock_guard lock(mutex_);
  const auto found = by_digest_.find(digest);
  if (found == by_digest_.end()) return nullptr;
  recent_.splice(recent_.begin(), recent_, found->second);
  recount(*found->second);  // pairs running on it may have prepared more
  std::shared_ptr<const Scan> scan = found->second->scan;  // held from here: it stays while others leave
  evict(leaving);
  return scan;
}

std::shared_ptr<const ScanCache::Scan> ScanCache::insert(const std::string& digest, PointCloud cloud) {
  auto scan = std::make_shared<const Scan>(std::move(cloud));
  const std::size_t bytes = scan->bytes();
  std::vector<std::shared_ptr<const Scan>> leaving;
  const std::lock_guard lock(mutex_);
  if (const auto found = by_digest_.find(digest); found != by_digest_.end()) {
    recent_.splice(recent_.begin(), recent_, found->second);
    return found->second->scan;
  }
  if (bytes > budget_) return scan;  // used by this pair, kept by none
  recent_.push_front({digest, scan, bytes});
  by_digest_[digest] = recent_.begin();
  bytes_ += bytes;
  evict(leaving);  // the new scan is held by this pair: it stays
  return scan;
}

void ScanCache::release(std::shared_ptr<const Scan> scan) {
  if (!scan) return;
  std::vector<std::shared_ptr<const Scan>> leaving;
  const std::lock_guard lock(mutex_);
  for (Held& held : recent_)
    if (held.scan == scan) {
      scan.reset();  // before evicting: this pair no longer holds it
      recount(held);
      break;
    }
  evict(leaving);
}

std::size_t ScanCache::bytes() const {
  const std::lock_guard lock(mutex_);
  return bytes_;
}

void ScanCache::recount(Held& held) {
  bytes_ -= held.bytes;
  held.bytes = held.scan->bytes();
  bytes_ += held.bytes;
}

void ScanCache::evict(std::vector<std::shared_ptr<const Scan>>& leaving) {
  for (auto it = recent_.end(); bytes_ > budget_ && it != recent_.begin();) {
    --it;
    // Only the cache holds it: no pair is using it, and none can take it while mutex_ is held.
    if (it->scan.use_count() != 1) continue;
    bytes_ -= it->bytes;
    by_digest_.erase(it->digest);
    leaving.push_back(std::move(it->scan));
    it = recent_.erase(it);
  }
}

}  // namespace k4reg::service
