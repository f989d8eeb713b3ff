// What the subcommands share: the check of numeric options, the options every study declares
// the same way, the interrupt flag, and the writing of a generated model.
#pragma once

#include <CLI/CLI.hpp>

#include <atomic>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

namespace railcrash::cli {

/// The one check of every numeric command-line option: a finite number within [low, high]
/// (an open end excluded). The message names the value and the option's valid range, e.g.
/// "--speed: 'inf' is not in range: give a finite number greater than 0 and at most 1000 [km/h]"
/// (CLI11 puts the option's name first). Integer options are checked here for their range and
/// by CLI11 for being whole.
CLI::Validator finite_number(double low, double high, bool low_open, bool high_open, const std::string& unit = "");

constexpr double kUnbounded = std::numeric_limits<double>::infinity();

// The ranges of the numeric options that several commands share.
CLI::Validator positive_number();   // greater than 0
CLI::Validator tolerance_range();   // a relative tolerance: between 0 and 1, both excluded
CLI::Validator seconds_range();     // [s] 0 or more

// The options the studies (sensitivity, readings, sweep, converge) share, declared here once:
// the same name, help text, default and check in each.

/// How many runs a study starts at once when --jobs is not given.
enum class JobsDefault {
  AllCores,          // 0: one job per core (sensitivity, readings, sweep)
  OneForWallTimes,   // 1: converge, whose wall times parallel load would make noisier
};
/// --jobs N: runs in parallel on this machine (a sweep under mpirun: on each rank).
void add_jobs_option(CLI::App& study, int& jobs, JobsDefault default_jobs);
/// --jobs as the study runs it: 0 (not given) is one job per core.
int jobs_to_run(int jobs);
/// --run-limit S: a run's wall time after which it is stopped and reported failed (0: no limit).
/// `former_name`: a second name the option had before it was declared once (converge's
/// --run-timeout), still accepted.
void add_run_limit_option(CLI::App& study, double& seconds, const std::string& former_name = "");
/// --max-runs N: refuse a study of more runs than this before any starts (0: no limit).
void add_max_runs_option(CLI::App& study, std::size_t& max_runs);
/// --design FILE: the sensitivity design ('report': sensitivity_design.yaml beside the model).
void add_design_option(CLI::App& study, std::string& design_path);
/// --first-order: skip the design's second-order runs and fit.
void add_first_order_option(CLI::App& study, bool& first_order_only);
/// --out DIR: the output folder of a run or a study (default "out").
void add_out_folder_option(CLI::App& command, std::string& folder);
/// --set KEY=VALUE or KEY*=FACTOR: a model key overridden (model_io.hpp load_model), repeatable.
void add_set_option(CLI::App& command, std::vector<std::string>& settings);

/// Raised by SIGINT and SIGTERM once catch_interrupts() has run: the runs in progress stop at
/// their next step, the results so far are written, and the command exits 1 (as a failed run).
std::atomic<bool>& interrupted();
void catch_interrupts();

/// Writes a generated model to out_path (standard output when empty); `what` names it on stderr.
int write_generated_model(const std::string& text, const std::string& out_path, const std::string& what);

/// `railcrash report RUN_DIR`: RUN_DIR/report.html (also `run --report`); report_command.cpp.
int write_run_report(const std::string& run_dir, double cfc, double force_cfc = 60.0, bool pdf = false);

}  // namespace railcrash::cli
