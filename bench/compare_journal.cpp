#include "compare_journal.h"

#include <algorithm>
#include <nlohmann/json.hpp>

namespace k4reg::bench {

using nlohmann::json;

NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(Errors, mae_deg, mte_m, rotation_deg, translation_m, rmse_m)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(Run, method, trial, ok, capped, success_coarse, success_final, error,
                                                coarse, final, stages, total_s, read_s, convert_s, peak_rss_mb,
                                                source_keypoints, target_keypoints, sift_overflow_octaves, attempts,
                                                foreign_cores)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(DetectorStats, ok, timed_out, error, source, target, repeatability,
                                                seconds, peak_rss_mb, sift_overflow_octaves, attempts, foreign_cores)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(KeypointStats, ran, ours, pcl, truth_overlap, plain_voxel_m)

Journal::Journal(const std::string& path, bool resume, std::string session_started)
    : path_(path), session_started_(std::move(session_started)) {
  if (resume) {
    std::map<std::string, double> session_lengths;  // by start time
    std::ifstream in(path);
    for (std::string line; std::getline(in, line);) {
      if (line.empty()) continue;
      json entry;
      try {
        entry = json::parse(line);
      } catch (const json::exception&) {
        continue;  // a line cut short when the orchestrator was killed
      }
      const std::string session = entry.value("session", "");
      double& length = session_lengths[session];
      length = std::max(length, entry.value("elapsed_s", 0.0));
      if (replay_.first_started.empty()) replay_.first_started = session;
      const std::string label = entry.value("case", "");
      if (entry.contains("keypoints")) replay_.keypoints[label] = entry["keypoints"].get<KeypointStats>();
      if (entry.contains("run")) {
        const Run run = entry["run"].get<Run>();
        replay_.runs[{label, run.method, run.trial}] = run;
      }
    }
    for (const auto& [session, length] : session_lengths) replay_.earlier_sessions_s += length;
    replay_.sessions = static_cast<int>(session_lengths.size());
  }
  // A new journal replaces the old one at once; a resumed one is opened at its first entry (a report from
  // the journal alone must not create one).
  if (!resume) out_.open(path, std::ios::trunc);
}

void Journal::add(const std::string& case_label, const KeypointStats& keypoints, double session_elapsed_s) {
  append({{"keypoints", keypoints}}, case_label, session_elapsed_s);
}

void Journal::add(const std::string& case_label, const Run& run, double session_elapsed_s) {
  append({{"run", run}}, case_label, session_elapsed_s);
}

void Journal::append(json entry, const std::string& case_label, double session_elapsed_s) {
  entry["case"] = case_label;
  entry["session"] = session_started_;
  entry["elapsed_s"] = session_elapsed_s;
  if (!out_.is_open()) out_.open(path_, std::ios::app);
  out_ << entry.dump() << std::endl;  // flushed: the line survives a kill
}

}  // namespace k4reg::bench
