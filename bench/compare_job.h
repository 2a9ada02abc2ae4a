// One run of the comparison: what the orchestrator hands to a worker process (as JSON on its command
// line) and what the worker prints back (one JSON line). Each run gets a fresh process so its peak
// RSS (getrusage of the child) belongs to that method alone, and a runaway run can be killed.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

namespace k4reg::bench {

// Methods (the value of Job::method).
inline constexpr const char* kOursK4pcs = "k4pcs-ours";     // register_clouds, K-4PCS, with ICP
inline constexpr const char* kPclK4pcs = "k4pcs-pcl";       // SIFTKeypoint + KFPCSInitialAlignment
inline constexpr const char* kOursPlain = "4pcs-ours";      // register_clouds, plain 4PCS on a coarse grid
inline constexpr const char* kPclPlain = "4pcs-pcl";        // VoxelGrid + FPCSInitialAlignment
inline constexpr const char* kOursMatch = "match-ours";     // match_4pcs on given keypoints (ETH office)
inline constexpr const char* kPclMatch = "match-pcl";       // KFPCSInitialAlignment on given keypoints
inline constexpr const char* kKeypointsOurs = "keypoints-ours";  // our detector once per pair: counts, repeatability
inline constexpr const char* kKeypointsPcl = "keypoints-pcl";    // PCL's SIFTKeypoint likewise, kept for the trials
// Feature-based peers (issue 49), on a voxel grid at sigma: FPFH matching instead of 4PCS.
inline constexpr const char* kPclSacIa = "fpfh-sacia-pcl";          // FPFHEstimationOMP + SAC-IA (fpfh_methods.h)
inline constexpr const char* kOpen3dRansac = "fpfh-ransac-open3d";  // Open3D FPFH + RANSAC (open3d_peer.h)
inline constexpr const char* kOpen3dFgr = "fgr-open3d";             // Open3D FPFH + fast global registration

// PCL checks its time cap only between iterations (and SIFTKeypoint has none), so the orchestrator kills
// a run still going kHardLimitSlack_s after its cap.
inline constexpr double kHardLimitSlack_s = 15.0;

struct Job {
  std::string method;
  std::string source, target;                               // cloud files
  Eigen::Matrix4d truth = Eigen::Matrix4d::Identity();      // T_target_source in the files' frames and units
  double unit_scale = 1.0;      // coordinates (and the truth's translation) are multiplied by this on reading
  double max_range_m = 0.0;     // points farther than this from the file origin (the scanner) are dropped; 0 = none
  std::uint64_t pose_seed = 0;  // != 0: the source is moved by a random rigid motion (truth adjusted)
  double sigma_m = 0.05;        // DoG minimum scale = voxel spacing = 4PCS delta for the keypoint methods
  double overlap = 0.8;
  double plain_voxel_m = 0.0;   // grid spacing of the plain-4PCS methods (and their delta)
  std::uint64_t seed = 1;       // ours only: PCL seeds itself with time()
  int max_bases = 0;            // ours: 0 = from the overlap
  int pcl_iterations = 100;     // PCL's setMaximumIterations
  int cap_s = 600;              // wall-time cap of one run (PCL: setMaxComputationTime; ours: time_budget_s)
  int memory_cap_mb = 12000;    // address-space limit of the worker: a run past it fails (bad_alloc)
  std::string sift_cache_dir;   // PCL's SIFT keypoints per scan (see sift_cache.h); "" = computed in every run
};

void to_json(nlohmann::json& j, const Job& job);
void from_json(const nlohmann::json& j, Job& job);

// Limits this process's address space to job.memory_cap_mb (so a runaway run fails instead of pushing a
// shared machine into the OOM killer). A bad_alloc that escapes where run_job cannot catch it (PCL throws
// from inside OpenMP regions) still ends the process, but first prints kOutOfMemoryLine.
void limit_memory(const Job& job);
inline constexpr const char* kOutOfMemoryLine = "OUT_OF_MEMORY";

// Runs the job in this process and returns the result object (see compare_worker.cpp for the fields).
nlohmann::json run_job(const Job& job);

}  // namespace k4reg::bench
