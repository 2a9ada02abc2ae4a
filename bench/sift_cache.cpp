#include "sift_cache.h"

#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>

namespace k4reg::bench {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kRunningSuffix = ".running";
constexpr const char* kTimedOutSuffix = ".timedout";

std::string full_key(const std::string& scan_key, bool use_intensity, const SiftParams& p) {
  char buffer[160];
  std::snprintf(buffer, sizeof buffer, "|sigma=%.6g|octaves=%d|scales=%d|contrast=%.6g|intensity=%d", p.min_scale_m,
                p.octaves, p.scales_per_octave, p.min_contrast_fraction, use_intensity ? 1 : 0);
  return scan_key + buffer;
}

fs::path entry_path(const std::string& dir, const std::string& key) {
  char name[40];
  std::snprintf(name, sizeof name, "sift-%016zx", std::hash<std::string>{}(key));
  return fs::path(dir) / name;
}

double own_peak_rss_mb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;
}

void write_atomically(const fs::path& path, const std::string& text) {
  const fs::path temporary = path.string() + ".tmp";
  std::ofstream(temporary) << text;
  fs::rename(temporary, path);
}

}  // namespace

SceneSift SiftCache::keypoints(const PointCloud& cloud, const std::string& scan_key, bool use_intensity,
                               const SiftParams& params, int cap_s,
                               const std::function<void(const PclCloud&)>& before_computing) const {
  const std::string key = full_key(scan_key, use_intensity, params);
  const fs::path entry = dir_.empty() ? fs::path() : entry_path(dir_, key);
  if (!dir_.empty()) {
    fs::create_directories(dir_);
    if (std::ifstream in(entry.string() + ".json"); in) {
      const json j = json::parse(in);
      if (j.at("key") == key) {
        SceneSift out;
        const auto xyz = j.at("points").get<std::vector<float>>();
        for (std::size_t i = 0; i + 2 < xyz.size(); i += 3) out.points.emplace_back(xyz[i], xyz[i + 1], xyz[i + 2]);
        out.seconds = j.at("seconds");
        out.peak_rss_mb = j.at("peak_rss_mb");
        out.overflowed_octaves = j.at("overflowed_octaves");
        out.from_cache = true;
        return out;
      }
    }
    if (std::ifstream in(entry.string() + kTimedOutSuffix); in) {
      int marked_cap_s = 0;
      in >> marked_cap_s;
      if (cap_s <= marked_cap_s)
        throw SiftTimedOutEarlier("SIFTKeypoint on this scan passed the hard limit in an earlier job (cap " +
                                 std::to_string(marked_cap_s) + " s); it is deterministic, so it is not run again");
    }
    write_atomically(entry.string() + kRunningSuffix, key + "\n");
  }

  SceneSift out;
  const PclCloud::Ptr pcl_cloud = to_pcl(cloud);
  before_computing(*pcl_cloud);
  const auto start = std::chrono::steady_clock::now();
  const SiftKeypoints sift = pcl_sift_keypoints(pcl_cloud, use_intensity, params);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  out.points = to_points(*sift.points);
  out.overflowed_octaves = sift.overflowed_octaves;
  out.peak_rss_mb = own_peak_rss_mb();
  if (!dir_.empty()) {
    std::vector<float> xyz;
    for (const auto& p : out.points) xyz.insert(xyz.end(), {p.x(), p.y(), p.z()});
    const json j = {{"key", key},
                    {"seconds", out.seconds},
                    {"peak_rss_mb", out.peak_rss_mb},
                    {"overflowed_octaves", out.overflowed_octaves},
                    {"points", xyz}};
    write_atomically(entry.string() + ".json", j.dump());
    fs::remove(entry.string() + kRunningSuffix);
  }
  return out;
}

void SiftCache::mark_running_as_timed_out(int cap_s) const {
  if (dir_.empty() || !fs::exists(dir_)) return;
  for (const auto& file : fs::directory_iterator(dir_)) {
    if (file.path().extension() != kRunningSuffix) continue;
    fs::path marked = file.path();
    marked.replace_extension(kTimedOutSuffix);
    std::ofstream(marked) << cap_s << "\n";
    fs::remove(file.path());
  }
}

void SiftCache::forget_running() const {
  if (dir_.empty() || !fs::exists(dir_)) return;
  for (const auto& file : fs::directory_iterator(dir_))
    if (file.path().extension() == kRunningSuffix) fs::remove(file.path());
}

}  // namespace k4reg::bench
