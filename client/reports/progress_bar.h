// Progress of `k4reg register` on stderr: a bar redrawn in place (bytes, rate, then the job's stages) for a
// terminal, or one plain line per event (upload done, queued, stage started/finished, retry) for logs.
#pragma once

#include <chrono>
#include <ostream>
#include <string>

#include "remote/remote_registration.h"

namespace k4reg::cli {

class ProgressBar : public RegistrationObserver {
 public:
  enum class Style { kBar, kLines };
  ProgressBar(std::ostream& out, Style style);
  ~ProgressBar() override;  // ends a bar line still open, so what follows starts on a fresh line
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  void on_upload(std::uint64_t sent_bytes, std::uint64_t total_bytes) override;
  void on_event(const v1::RegisterStreamResponse& event) override;
  void on_retry(const std::string& code, double backoff_s, int attempt, int attempts) override;

 private:
  using Clock = std::chrono::steady_clock;
  // Bar: overwrites the current line (throttled unless `force`); lines: prints `text` as a line of its own.
  void redraw(const std::string& text, bool force);
  void end_line();
  void print_line(const std::string& text);

  std::ostream& out_;
  Style style_;
  Clock::time_point upload_start_, last_draw_;
  bool line_open_ = false;
};

// "2.6 MB", "850 kB": decimal units, as network rates are usually given.
std::string human_bytes(double bytes);

}  // namespace k4reg::cli
