// PCL's SIFT keypoints of one scan, computed once and kept on disk. SIFTKeypoint is deterministic, so
// every trial of a pair, and every pair sharing the scan, starts from the same keypoints together with
// the time and memory their computation took (measured when computed, in the process that did it).
// Costs: one JSON file of a few hundred kB per scan and sigma.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "k4reg/geometry/point_cloud.h"
#include "pcl_methods.h"

namespace k4reg::bench {

struct SceneSift {
  std::vector<Eigen::Vector3f> points;  // in the loaded cloud's local frame
  double seconds = 0.0;                 // SIFT alone (copying into a PCL cloud is not counted)
  double peak_rss_mb = 0.0;             // of the process that computed them, right after
  int overflowed_octaves = 0;
  bool from_cache = false;
};

// SIFT on this scan was killed at the hard limit before (SIFT would only do the same again).
struct SiftTimedOutEarlier : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class SiftCache {
 public:
  // dir "" = no cache: every call computes.
  explicit SiftCache(std::string dir) : dir_(std::move(dir)) {}

  // scan_key names the cloud exactly (file, unit scale, range limit, pose applied). before_computing sees
  // the PCL cloud SIFT is about to run on (not called on a cache hit). Throws SiftTimedOutEarlier when an
  // earlier job was killed while computing this scan with a cap of at least cap_s.
  SceneSift keypoints(const PointCloud& cloud, const std::string& scan_key, bool use_intensity,
                      const SiftParams& params, int cap_s,
                      const std::function<void(const PclCloud&)>& before_computing) const;

  // Orchestrator side, after it killed a keypoint job: the scan that job was computing is marked timed
  // out under cap_s. At start-up: forgets the marks of computations an earlier, interrupted orchestrator
  // left behind (no job runs then).
  void mark_running_as_timed_out(int cap_s) const;
  void forget_running() const;

 private:
  std::string dir_;
};

}  // namespace k4reg::bench
