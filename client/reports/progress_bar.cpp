#include "reports/progress_bar.h"

#include <fmt/format.h>

#include <algorithm>

namespace k4reg::cli {
namespace {

constexpr int kBarWidth = 24;
// Redrawing for every 1 MiB chunk would flood a slow terminal; stage events are already rate-limited by the server.
constexpr auto kRedrawInterval = std::chrono::milliseconds(100);

std::string bar(double fraction) {
  const int filled = static_cast<int>(std::clamp(fraction, 0.0, 1.0) * kBarWidth + 0.5);
  return "[" + std::string(filled, '#') + std::string(kBarWidth - filled, '-') + "]";
}

}  // namespace

std::string human_bytes(double bytes) {
  constexpr const char* kUnits[] = {"B", "kB", "MB", "GB", "TB"};
  int unit = 0;
  while (bytes >= 1000 && unit < 4) {
    bytes /= 1000;
    ++unit;
  }
  return unit == 0 ? fmt::format("{:.0f} B", bytes) : fmt::format("{:.1f} {}", bytes, kUnits[unit]);
}

ProgressBar::ProgressBar(std::ostream& out, Style style) : out_(out), style_(style) {}

ProgressBar::~ProgressBar() { end_line(); }

void ProgressBar::on_upload(std::uint64_t sent, std::uint64_t total) {
  const Clock::time_point now = Clock::now();
  if (sent == 0) upload_start_ = now;  // every upload, a retry's too, starts with 0 bytes sent
  const double seconds = std::chrono::duration<double>(now - upload_start_).count();
  const std::string rate = seconds > 0 ? human_bytes(static_cast<double>(sent) / seconds) + "/s" : "";
  const bool done = sent == total;
  if (style_ == Style::kLines) {
    if (done)
      print_line(fmt::format("uploaded {} in {:.3f} s{}", human_bytes(static_cast<double>(total)), seconds,
                             rate.empty() ? "" : " (" + rate + ")"));
    return;
  }
  const double fraction = static_cast<double>(sent) / static_cast<double>(total);
  redraw(fmt::format("{:<14} {} {:3.0f}%  {} / {}  {}", "upload", bar(fraction), 100.0 * fraction,
                     human_bytes(static_cast<double>(sent)), human_bytes(static_cast<double>(total)), rate),
         done);
  if (done) end_line();  // the upload's summary stays; the stages draw on the next line
}

void ProgressBar::on_event(const v1::RegisterStreamResponse& event) {
  if (event.has_queued()) {
    const std::string text = fmt::format("queued at position {}", event.queued().position());
    style_ == Style::kBar ? redraw(text, true) : print_line(text);
    return;
  }
  if (!event.has_stage()) return;
  const v1::StageEvent& stage = event.stage();
  if (style_ == Style::kBar) {
    redraw(fmt::format("{:<14} {} {:3.0f}%  {:.2f} s", stage.stage(), bar(stage.fraction()), 100.0 * stage.fraction(),
                       stage.elapsed_s()),
           stage.phase() != v1::StageEvent::PHASE_PROGRESS);
  } else if (stage.phase() == v1::StageEvent::PHASE_STARTED) {
    print_line(fmt::format("{} started at {:.2f} s", stage.stage(), stage.elapsed_s()));
  } else if (stage.phase() == v1::StageEvent::PHASE_FINISHED) {
    print_line(fmt::format("{} finished at {:.2f} s", stage.stage(), stage.elapsed_s()));
  }
}

void ProgressBar::on_retry(const std::string& code, double backoff_s, int attempt, int attempts) {
  print_line(fmt::format("{}: retrying in {:.1f} s (attempt {} of {})", code, backoff_s, attempt, attempts));
}

void ProgressBar::redraw(const std::string& text, bool force) {
  const Clock::time_point now = Clock::now();
  if (!force && line_open_ && now - last_draw_ < kRedrawInterval) return;
  last_draw_ = now;
  out_ << "\r\x1b[K" << text << std::flush;  // carriage return + erase line: redraw in place
  line_open_ = true;
}

void ProgressBar::end_line() {
  if (!line_open_) return;
  out_ << "\n" << std::flush;
  line_open_ = false;
}

void ProgressBar::print_line(const std::string& text) {
  end_line();
  out_ << text << "\n" << std::flush;
}

}  // namespace k4reg::cli
