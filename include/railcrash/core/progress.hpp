// Progress of one run, on stderr: on a terminal a bar with the simulated time, the rate
// (simulated seconds per wall-clock second) and the time left, redrawn at most five times a
// second; when stderr is not a terminal (a log file, a pipe, a batch job) one line every few
// seconds, so that a long piped run is not silent until it ends.
#pragma once

#include <chrono>
#include <cstdio>
#include <string>

namespace railcrash {

class ProgressMeter {
 public:
  enum class Style { Off, Bar, Lines };
  /// Bar on a terminal, else Lines; Off when `show` is false.
  static Style style_for(bool show, std::FILE* out);

  ProgressMeter(double t_end, Style style, std::FILE* out = stderr, double line_interval = 5.0 /* [s] wall clock */);
  /// Called at every output sample with the simulated time t.
  void update(double t);
  /// Ends the bar's line (or prints the last line) once the run is over.
  void finish(double t);

  /// "[#######.......]  42%  t = 0.105 of 0.25 s  0.09 s/s  1.6 s left"
  static std::string bar_text(double t, double t_end, double elapsed_seconds, int width = 30);
  /// "progress: t = 0.105 of 0.25 s (42%), 0.09 simulated s per s, about 1.6 s left"
  static std::string line_text(double t, double t_end, double elapsed_seconds);

 private:
  double t_end_;
  Style style_;
  std::FILE* out_;
  double line_interval_;
  std::chrono::steady_clock::time_point start_, last_;
  bool drawn_ = false;
};

}  // namespace railcrash
