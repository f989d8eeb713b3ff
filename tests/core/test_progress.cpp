// Run progress: the bar's and the line's text, and the line mode writing to a file.
#include <catch2/catch.hpp>

#include <cstdio>
#include <string>

#include "railcrash/core/progress.hpp"
#include "railcrash/core/version.hpp"

using railcrash::ProgressMeter;

TEST_CASE("Progress text: fraction, rate and time left", "[progress]") {
  // A quarter of 0.4 s simulated in 2 s of wall time: 0.05 s/s, 6 s left.
  CHECK(ProgressMeter::bar_text(0.1, 0.4, 2.0, 8) == "[##......]  25%  t = 0.1 of 0.4 s  0.05 s/s  6 s left");
  CHECK(ProgressMeter::line_text(0.1, 0.4, 2.0) == "progress: t = 0.1 of 0.4 s (25%), 0.05 simulated s per s, about 6 s left");
  CHECK(ProgressMeter::line_text(0.0, 0.4, 0.0) == "progress: t = 0 of 0.4 s (0%), 0 simulated s per s, about ? left");
  CHECK(ProgressMeter::bar_text(0.4, 0.4, 100.0, 4) == "[####] 100%  t = 0.4 of 0.4 s  0.004 s/s  0 s left");
  // Long runs in minutes and hours.
  CHECK_THAT(ProgressMeter::line_text(1.0, 100.0, 60.0), Catch::EndsWith("about 99 min left"));
  CHECK_THAT(ProgressMeter::line_text(1.0, 1000.0, 60.0), Catch::EndsWith("about 16.6 h left"));
}

TEST_CASE("Progress lines when the output is not a terminal, nothing when off", "[progress]") {
  std::FILE* file = std::tmpfile();
  REQUIRE(file);
  CHECK(ProgressMeter::style_for(true, file) == ProgressMeter::Style::Lines);
  CHECK(ProgressMeter::style_for(false, file) == ProgressMeter::Style::Off);
  {
    ProgressMeter meter(1.0, ProgressMeter::Style::Lines, file, 0.0);  // a line at every update
    meter.update(0.5);
    meter.update(1.0);
    meter.finish(1.0);
    ProgressMeter off(1.0, ProgressMeter::Style::Off, file, 0.0);
    off.update(0.5);
    off.finish(1.0);
  }
  std::rewind(file);
  std::string text;
  for (int c; (c = std::fgetc(file)) != EOF;) text += static_cast<char>(c);
  std::fclose(file);
  CHECK_THAT(text, Catch::StartsWith("progress: t = 0.5 of 1 s (50%)"));
  std::size_t lines = 0;
  for (char c : text) lines += c == '\n';
  CHECK(lines == 3);
}

TEST_CASE("Version text names the libraries", "[progress]") {
  const std::string text = railcrash::version_text();
  CHECK_THAT(text, Catch::StartsWith("railcrash 0.") && Catch::Contains("\nSUNDIALS 6.") && Catch::Contains("\nSuiteSparse ") &&
                       Catch::Contains("(KLU ") && Catch::Contains("\nEigen 3."));
}
