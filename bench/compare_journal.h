// The comparison's journal: every finished keypoint job and run is appended as one JSON line the moment
// it ends. A full comparison takes hours; when it is interrupted, `--resume` replays the journal and runs
// only what is missing, so no finished run is lost or repeated. Resume only with the same build and
// options: entries are matched by case label, method and trial.
#pragma once

#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <tuple>

#include "compare_report.h"

namespace k4reg::bench {

struct JournalReplay {
  std::map<std::string, KeypointStats> keypoints;                     // by case label
  std::map<std::tuple<std::string, std::string, int>, Run> runs;      // by case label, method, trial
  std::string first_started;  // when the first session began ("" = no earlier session)
  double earlier_sessions_s = 0.0;
  int sessions = 0;
};

class Journal {
 public:
  // resume = false starts a new journal (the old one is overwritten).
  Journal(const std::string& path, bool resume, std::string session_started);

  const JournalReplay& replay() const { return replay_; }
  void add(const std::string& case_label, const KeypointStats& keypoints, double session_elapsed_s);
  void add(const std::string& case_label, const Run& run, double session_elapsed_s);

 private:
  void append(nlohmann::json entry, const std::string& case_label, double session_elapsed_s);
  JournalReplay replay_;
  std::string path_;
  std::string session_started_;
  std::ofstream out_;
};

}  // namespace k4reg::bench
