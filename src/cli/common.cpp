#include "common.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <thread>

#include "railcrash/core/whole_file.hpp"
#include "railcrash/studies/run_count.hpp"  // kDefaultMaxRuns

namespace railcrash::cli {

namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_interrupt(int) { g_stop.store(true); }

constexpr double kMaxJobs = 65536;  // --jobs: threads asked for (batch.cpp runs with those it can have)

}  // namespace

CLI::Validator finite_number(double low, double high, bool low_open, bool high_open, const std::string& unit) {
  const auto limit = [](double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", value);
    return std::string(text);
  };
  std::string range = "a finite number";
  if (std::isfinite(low)) range += (low_open ? " greater than " : " of at least ") + limit(low);
  if (std::isfinite(high)) range += (std::isfinite(low) ? " and" : "") + std::string(high_open ? " less than " : " at most ") + limit(high);
  if (!unit.empty()) range += " [" + unit + "]";
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        const char* first = text.c_str();
        char* end = nullptr;
        errno = 0;
        const double value = std::strtod(first, &end);
        if (end == first || *end != '\0') return "'" + text + "' is not a number: give " + range;
        const bool inside = std::isfinite(value) && (low_open ? value > low : value >= low) && (high_open ? value < high : value <= high);
        if (!inside) return "'" + text + "' is not in range: give " + range;
        return "";
      },
      range.substr(2), "finite_number");
}

CLI::Validator positive_number() { return finite_number(0, kUnbounded, true, false); }
CLI::Validator tolerance_range() { return finite_number(0, 1, true, true); }
CLI::Validator seconds_range() { return finite_number(0, kUnbounded, false, false, "s"); }

void add_jobs_option(CLI::App& study, int& jobs, JobsDefault default_jobs) {
  if (default_jobs == JobsDefault::AllCores) {
    jobs = 0;
    study.add_option("--jobs", jobs, "runs in parallel on this machine (default: all cores)")
        ->check(finite_number(0, kMaxJobs, false, false));
  } else {
    jobs = 1;
    study.add_option("--jobs", jobs, "runs in parallel on this machine (default 1: parallel load makes the wall times noisier)")
        ->capture_default_str()
        ->check(finite_number(1, kMaxJobs, false, false));
  }
}

int jobs_to_run(int jobs) { return jobs > 0 ? jobs : static_cast<int>(std::max(1u, std::thread::hardware_concurrency())); }

void add_run_limit_option(CLI::App& study, double& seconds, const std::string& former_name) {
  seconds = 0.0;
  study.add_option("--run-limit" + (former_name.empty() ? "" : "," + former_name), seconds,
                   "stop a run after this many seconds of wall time and report it failed (0: no limit)")
      ->capture_default_str()
      ->check(seconds_range());
}

void add_max_runs_option(CLI::App& study, std::size_t& max_runs) {
  max_runs = kDefaultMaxRuns;
  study.add_option("--max-runs", max_runs, "refuse a study of more runs than this before any starts (0: no limit)")
      ->capture_default_str()
      ->check(finite_number(0, 1e18, false, false));
}

void add_design_option(CLI::App& study, std::string& design_path) {
  design_path = "report";
  study.add_option("--design", design_path,
                   "design file: parameters, what they scale, second-order runs and terms, and for readings the published "
                   "results ('reference'); 'report' = sensitivity_design.yaml beside the model")
      ->capture_default_str();
}

void add_first_order_option(CLI::App& study, bool& first_order_only) {
  first_order_only = false;
  study.add_flag("--first-order", first_order_only, "skip the design's second-order runs and fit");
}

void add_out_folder_option(CLI::App& command, std::string& folder) {
  folder = "out";
  command.add_option("--out", folder, "output folder")->capture_default_str();
}

void add_set_option(CLI::App& command, std::vector<std::string>& settings) {
  command.add_option("--set", settings,
                     "override a model key (KEY=VALUE or KEY*=FACTOR), e.g. --set simulation.t_end=0.5 --set "
                     "elements.k1.stiffness=2e6");
}

std::atomic<bool>& interrupted() { return g_stop; }

void catch_interrupts() {
  std::signal(SIGINT, on_interrupt);
  std::signal(SIGTERM, on_interrupt);
}

int write_generated_model(const std::string& text, const std::string& out_path, const std::string& what) {
  if (out_path.empty()) {
    std::fputs(text.c_str(), stdout);
    return 0;
  }
  write_whole_file(out_path, text);
  std::fprintf(stderr, "%s written to %s\n", what.c_str(), out_path.c_str());
  return 0;
}

}  // namespace railcrash::cli
