#include "scan_cache.h"

#include "memory_budget.h"

namespace k4reg::service {

std::shared_ptr<const ScanCache::Scan> ScanCache::find(const std::string& digest) {
  const std::lock_guard lock(mutex_);
  const auto found = by_digest_.find(digest);
  if (found == by_digest_.end()) return nullptr;
  recent_.splice(recent_.begin(), recent_, found->second);
  return found->second->scan;
}

std::shared_ptr<const ScanCache::Scan> ScanCache::insert(const std::string& digest, PointCloud cloud) {
  const std::size_t bytes = kBytesPerPoint * cloud.size();
  auto scan = std::make_shared<const Scan>(std::move(cloud));
  const std::lock_guard lock(mutex_);
  if (const auto found = by_digest_.find(digest); found != by_digest_.end()) {
    recent_.splice(recent_.begin(), recent_, found->second);
    return found->second->scan;
  }
  if (bytes > budget_) return scan;  // used by this pair, kept by none
  // Pairs still running keep their scans (shared_ptr) when they leave the cache.
  while (!recent_.empty() && bytes_ + bytes > budget_) {
    bytes_ -= recent_.back().bytes;
    by_digest_.erase(recent_.back().digest);
    recent_.pop_back();
  }
  recent_.push_front({digest, scan, bytes});
  by_digest_[digest] = recent_.begin();
  bytes_ += bytes;
  return scan;
}

std::size_t ScanCache::bytes() const {
  const std::lock_guard lock(mutex_);
  return bytes_;
}

}  // namespace k4reg::service
