// `railcrash sweep`: a study over model keys (design of experiments, Monte Carlo, explicit run
// lists) run by the batch runner (batch.hpp), one row per run in runs.csv.
//
// Plan file (YAML; README "Sweeps"):
//   sweep: 1
//   design: full_factorial      # one_at_a_time | latin_hypercube | monte_carlo | runs
//   samples: 20                 # latin_hypercube, monte_carlo
//   seed: 7                     # latin_hypercube, monte_carlo (default 1)
//   set: [simulation.t_end=0.2] # settings applied to every run (optional)
//   factors:
//     - key: elements.anticlimber.horizontal_yield_deflection
//       scale: true             # the levels multiply the model's value (KEY*=LEVEL)
//       levels: [0.8, 1.0, 1.2] # full_factorial, one_at_a_time, runs
//     - key: bodies.car1_center_body.velocity[0]     # one entry of a list
//       distribution: {uniform: [-500, -400]}        # or {normal: [mean, standard deviation]}
//   runs:                       # design: runs; each run lists levels by key (others: the model's value)
//     - {elements.anticlimber.horizontal_yield_deflection: 1.1}
//   responses: [responses.R1, car_crush.car1.max_crush, anticlimber.force@0.05]
//
// Responses are paths into summary.json (keys joined by dots, e.g.
// peak_accelerations.bodies.car1_center_body.magnitude_cfc.g) or COLUMN@TIME, a column of
// timeseries.csv interpolated linearly at TIME [s]; R1, R2, R3 are short for responses.R1...
//
// Designs. Levels are the listed values; "the model's value" is the run without a setting.
//   full_factorial   every combination of levels; the first factor changes slowest.
//   one_at_a_time    run 0 with every factor at the model's value, then each factor at each of
//                    its levels with the others at the model's value.
//   latin_hypercube  N samples; each factor's range of probability is cut into N equal strata
//                    and every stratum holds exactly one sample (McKay, Beckman and Conover
//                    1979), the strata matched at random between factors.
//   monte_carlo      N independent samples.
// Sampled designs draw from std::mt19937_64 (its output is fixed by the C++ standard) with this
// file's own transforms, so a seed gives the same runs on every platform: u = (k + 0.5) / 2^52
// from the top 52 bits k (exact, in (0, 1)), x = a + (b - a) u (uniform), x = mean + sd * Phi^-1(u) (normal, by
// bisection on Phi to 2^-60 of the range).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "railcrash/model/yaml_file.hpp"
#include "railcrash/studies/batch.hpp"
#include "railcrash/studies/run_count.hpp"

namespace railcrash {

struct SweepDistribution {
  enum class Kind { uniform, normal };
  Kind kind = Kind::uniform;
  double first = 0.0, second = 0.0;  // uniform: lower, upper bound; normal: mean, standard deviation
  double value_at(double probability) const;  // the quantile
};

struct SweepFactor {
  std::string key;                     // model key; "bodies.b.velocity[0]" sets one entry of a list
  bool scale = false;                  // values multiply the model's number (KEY*=VALUE)
  std::vector<std::string> levels;     // YAML text of each level
  std::optional<SweepDistribution> distribution;
  int line = 0;                        // in the plan file
  std::string column() const { return scale ? key + "*" : key; }
};

enum class SweepDesignKind { full_factorial, one_at_a_time, latin_hypercube, monte_carlo, runs };

struct SweepPlan {
  std::string path;
  SweepDesignKind design = SweepDesignKind::full_factorial;
  int design_line = 0;
  std::size_t samples = 0;
  std::uint64_t seed = 1;
  std::vector<std::string> settings;             // every run, before the factors
  std::vector<SweepFactor> factors;
  std::vector<std::vector<std::string>> runs;    // design runs: per run, per factor ("" = the model's value)
  std::vector<int> run_lines;
  std::vector<std::string> responses;
};

/// Reads a plan and checks it against the model (every key and level is applied to the model
/// once): InputError with the plan's file:line before any run.
SweepPlan load_sweep_plan(const std::string& path, const std::string& model_path);

// ---- design generators (tested against their definitions)

/// Level numbers of every combination; the first factor changes slowest.
std::vector<std::vector<std::size_t>> full_factorial(const std::vector<std::size_t>& level_counts);
/// Row 0: every factor at the model's value (-1); then factor i at each level j (others -1).
std::vector<std::vector<long>> one_at_a_time(const std::vector<std::size_t>& level_counts);
/// A uniform number in (0, 1) from the top 52 bits of one draw.
double unit_uniform(std::mt19937_64& generator);
/// samples x factors probabilities in (0, 1), one per stratum [k/N, (k+1)/N) in every column.
std::vector<std::vector<double>> latin_hypercube(std::size_t samples, std::size_t factors, std::uint64_t seed);
/// samples x factors independent probabilities in (0, 1).
std::vector<std::vector<double>> monte_carlo(std::size_t samples, std::size_t factors, std::uint64_t seed);
/// Phi^-1(p), the standard normal quantile.
double normal_quantile(double probability);

// ---- runs

struct SweepRunSpec {
  std::vector<std::string> levels;     // per factor, YAML text ("" = the model's value)
  std::vector<std::string> settings;   // what is applied to the model: the plan's, then the factors' (KEY=LEVEL, KEY*=LEVEL)
  std::string hash;                    // 16 hex digits of FNV-1a over everything the run reads (below)
};

/// The plan's runs, generated one at a time: run k is made from k alone (the full factorial's
/// k by its mixed-radix digits, the first factor slowest; one at a time's by the level counts;
/// Monte Carlo's from draws k x factors on of the seed's sequence), so a plan of any size is
/// counted and run without a list of its runs. A Latin hypercube's strata are matched by
/// shuffles of the whole design: it holds its samples x factors probabilities (8 bytes each).
/// `model_text` is the text of the model file at `model_path`. A run's hash covers everything it
/// reads: railcrash's and its libraries' versions (version_text), the text of every model file
/// (the model and, for a variant, its base: model_input_texts) and the run's settings in order
/// (the plan's `set`, then each factor's). Safe to call from several threads. `plan` must
/// outlive the generator.
class SweepRunGenerator {
 public:
  /// InputError when the plan has more runs than std::size_t holds.
  SweepRunGenerator(const SweepPlan& plan, const std::string& model_path, const std::string& model_text);
  std::size_t count() const { return count_; }
  /// Run k's level of each factor, YAML text ("" = the model's value); k < count().
  std::vector<std::string> levels(std::size_t k) const;
  SweepRunSpec spec(std::size_t k) const;

 private:
  const SweepPlan& plan_;
  std::size_t count_ = 0;
  std::uint64_t inputs_hash_ = 0;          // FNV-1a over the version text and every model file
  std::vector<double> hypercube_;          // latin_hypercube: probabilities, samples x factors, row by row
  mutable std::mutex generator_mutex_;     // monte_carlo: the draws, kept where the last run left them
  mutable std::mt19937_64 generator_;
  mutable std::size_t generator_next_run_ = 0;
};

/// Every run of the plan in order (SweepRunGenerator's; for small plans and tests).
std::vector<SweepRunSpec> sweep_runs(const SweepPlan& plan, const std::string& model_path, const std::string& model_text);

/// `railcrash sweep --dry-run`: the plan's run count, then runs.csv's first columns (run, hash,
/// the factors' levels) of each run listed in `runs` (numbers past the count are left out).
std::string sweep_dry_run_text(const SweepPlan& plan, const SweepRunGenerator& generator, const std::vector<std::size_t>& runs);

/// The number of runs the plan has, counted without generating them (nullopt: more than
/// std::size_t holds): the product of the level counts (full factorial), 1 + their sum (one at
/// a time), samples, or the runs listed.
std::optional<std::size_t> sweep_run_count(const SweepPlan& plan);
/// InputError unless the plan has at most max_runs runs (0: no limit; run_count.hpp).
void require_sweep_run_count(const SweepPlan& plan, std::size_t max_runs);

struct SweepRow {
  std::string status;                  // "ok", "failed"
  std::vector<double> responses;       // NaN where the run has no such value
  double wall_seconds = 0.0;
  std::string message;
  std::string outcomes;                // the run's discrete outcome, with times (OutcomeSignature::text)
  std::string branch;                  // the same, order only (OutcomeSignature::order): runs with equal ones are on one branch
  IntegratorUsed integrator;           // the method the run used (batch.hpp): runs.csv's integrator_used, euler_from_t
};

/// Runs one specification (used by the thread pool and by MPI ranks); `model_text` is the model
/// file's text, checked once (check_model_text) for all the runs.
SweepRow run_sweep_spec(const SweepPlan& plan, const std::string& model_path, const CheckedYamlText& model_text,
                        const SweepRunSpec& spec, const RunControl& control, const std::string& run_folder = "");

/// runs.csv: header and one line per row (run number, hash, factors, status, responses,
/// wall_seconds, message, outcomes, branch, integrator_used, euler_from_t).
std::string sweep_csv_header(const SweepPlan& plan);
std::string sweep_csv_line(const SweepPlan& plan, std::size_t number, const SweepRunSpec& spec, const SweepRow& row);

struct SweepOptions {
  int jobs = 1;
  double run_time_limit = 0.0;              // [s]
  const std::atomic<bool>* stop = nullptr;
  bool resume = false;
  bool keep_runs = false;                   // per-run folders DIR/runs/NNNN
  std::size_t max_runs = kDefaultMaxRuns;   // a plan of more runs is refused before any is generated (0: no limit)
  std::function<void(std::size_t number, const SweepRow&, std::size_t done, std::size_t total)> progress;
  std::function<void(const std::string& text)> note;  // sweep_start_note's lines, when there are any, before the runs
};

struct SweepResult {
  std::size_t total = 0;                          // runs in the plan
  std::map<std::size_t, std::string> lines;       // runs.csv line of each run done, by run number (runs not done: none)
  std::size_t resumed = 0;                        // rows taken from an earlier runs.csv
  std::size_t stale_rows = 0;     // rows of the earlier runs.csv (resuming) whose hash is no run of the plan: dropped
  std::size_t stale_folders = 0;  // folders DIR/runs/NNNN of no row kept: removed
  std::size_t torn_row_line = 0;  // resuming: the line of the earlier runs.csv's last row, cut short (dropped); 0: none
  std::size_t done() const { return lines.size(); }
};

/// Starts DIR/runs.csv (or, resuming, reads the rows it has whose hash matches a run): the
/// result with the resumed lines set. The other rows of the earlier file are dropped (their runs
/// read other inputs, or are no runs of this plan). DIR/runs/ is made to match the new file: the
/// folder of a resumed row takes the row's new run number, every other run folder is removed.
/// InputError if a resumed file has other columns, or (with its line and column) anything that is
/// no complete row of them but for a last row cut short, which is dropped (torn_row_line).
/// The new runs.csv is written whole (write_whole_file); FileWriteError if it cannot be.
/// A row of an earlier runs.csv is matched to the run of its own number when that run's hash is
/// the row's; only when some row is not, every run's hash is computed (one at a time) to find
/// the rows' runs. Memory: the rows of the earlier file, never a list of the plan's runs.
SweepResult start_sweep(const SweepPlan& plan, const SweepRunGenerator& generator, const std::string& directory, bool resume);
/// Lines that say how many rows start_sweep dropped and folders it removed ("" when none).
std::string sweep_start_note(const SweepResult& result, const std::string& directory);
/// Appends one finished line to DIR/runs.csv (by write(2), every byte checked: a killed sweep
/// keeps it); FileWriteError naming the file when it cannot be written whole.
void append_sweep_line(const std::string& directory, const std::string& line);

/// The runs done whose status is not ok (runs.csv's status column).
std::size_t failed_sweep_runs(const SweepPlan& plan, const SweepResult& result);

/// Runs the plan with threads, writing DIR/runs.csv as runs finish and again in run order at
/// the end, and DIR/summary.md.
SweepResult run_sweep(const std::string& model_path, const SweepPlan& plan, const std::string& directory,
                      const SweepOptions& options);

/// Writes DIR/runs.csv (run order; runs not done are left out) and DIR/summary.md (main
/// effects); returns the Markdown.
std::string write_sweep(const SweepPlan& plan, const SweepResult& result, const std::string& directory);

}  // namespace railcrash
