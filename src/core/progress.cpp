// Run progress on stderr (see the header).
#include "railcrash/core/progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>

namespace railcrash {

namespace {

std::string seconds_text(double seconds) {
  char buffer[32];
  if (!std::isfinite(seconds)) return "?";
  if (seconds < 100.0) std::snprintf(buffer, sizeof buffer, "%.2g s", seconds);
  else if (seconds < 6000.0) std::snprintf(buffer, sizeof buffer, "%.0f min", seconds / 60.0);
  else std::snprintf(buffer, sizeof buffer, "%.1f h", seconds / 3600.0);
  return buffer;
}

double fraction_of(double t, double t_end) { return t_end > 0.0 ? std::clamp(t / t_end, 0.0, 1.0) : 1.0; }

/// Wall-clock seconds left at the rate so far (infinite before any progress).
double time_left(double t, double t_end, double elapsed) {
  if (!(t > 0.0) || !(elapsed > 0.0)) return INFINITY;
  return std::max(0.0, t_end - t) * elapsed / t;
}

}  // namespace

ProgressMeter::Style ProgressMeter::style_for(bool show, std::FILE* out) {
  if (!show) return Style::Off;
  return isatty(fileno(out)) ? Style::Bar : Style::Lines;
}

ProgressMeter::ProgressMeter(double t_end, Style style, std::FILE* out, double line_interval)
    : t_end_(t_end), style_(style), out_(out), line_interval_(line_interval), start_(std::chrono::steady_clock::now()), last_(start_) {}

std::string ProgressMeter::bar_text(double t, double t_end, double elapsed, int width) {
  const double fraction = fraction_of(t, t_end);
  const int filled = static_cast<int>(std::floor(fraction * width));
  char head[160];
  std::snprintf(head, sizeof head, "] %3.0f%%  t = %.4g of %.4g s  %.3g s/s  %s left", 100.0 * fraction, t, t_end,
                elapsed > 0.0 ? t / elapsed : 0.0, seconds_text(time_left(t, t_end, elapsed)).c_str());
  return "[" + std::string(static_cast<std::size_t>(filled), '#') + std::string(static_cast<std::size_t>(width - filled), '.') + head;
}

std::string ProgressMeter::line_text(double t, double t_end, double elapsed) {
  char text[200];
  std::snprintf(text, sizeof text, "progress: t = %.4g of %.4g s (%.0f%%), %.3g simulated s per s, about %s left", t, t_end,
                100.0 * fraction_of(t, t_end), elapsed > 0.0 ? t / elapsed : 0.0, seconds_text(time_left(t, t_end, elapsed)).c_str());
  return text;
}

void ProgressMeter::update(double t) {
  if (style_ == Style::Off) return;
  const auto now = std::chrono::steady_clock::now();
  const double since_last = std::chrono::duration<double>(now - last_).count();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  if (style_ == Style::Bar) {
    if (since_last < 0.2 && drawn_) return;
    std::fprintf(out_, "\r%s\033[K", bar_text(t, t_end_, elapsed).c_str());
  } else {
    if (since_last < line_interval_) return;
    std::fprintf(out_, "%s\n", line_text(t, t_end_, elapsed).c_str());
  }
  std::fflush(out_);
  last_ = now;
  drawn_ = true;
}

void ProgressMeter::finish(double t) {
  if (style_ == Style::Off) return;
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (style_ == Style::Bar) std::fprintf(out_, "\r%s\033[K\n", bar_text(t, t_end_, elapsed).c_str());
  else if (drawn_) std::fprintf(out_, "%s\n", line_text(t, t_end_, elapsed).c_str());
  std::fflush(out_);
}

}  // namespace railcrash
