// Parameter studies in the manner of the report's Section 4 (Tables 9-17, equations 1-3;
// models/report/TRANSCRIPTION.md sections 11-15).
//
// Runs. A base run (every nondimensional parameter P = 1, i.e. the model's value), one run per
// parameter at the design's factor (1.2 in the report: Table 11), or two at 1 +- h (central
// differences), and the design's second-order runs (Table 12: several parameters set at once,
// e.g. P6 = 0.8, or P6 = P7 = 1.2). Each run gives R1-R3 (responses.hpp). Runs go in parallel;
// a failed run is reported and the others go on. The model file is read once, at the start, so
// every run sees the same model even if the file is edited while the study runs.
//
// First-order fit (equations 1-3). R = A0 + sum_i A_i P_i with
//   A_i = (R(run i) - R(base)) / (factor - 1)            (central: (R(1+h) - R(1-h)) / 2h)
//   A0  = R(base) - sum_i A_i                              (every P_i = 1 in the base run)
// A_i is the sensitivity the report ranks in Tables 15-17 (by |A_i|).
//
// Second-order fit (report Section 4.4, "reduced second-order form"). With the parameters that
// matter most, R = A0 + sum_i A_i P_i + sum_(i<=j) B_ij P_i P_j, keeping only the quadratic
// terms the design lists (the report keeps 8 linear and 8 quadratic terms: 17 constants). Each
// run that varies only term parameters (the base run, their first-order runs and the
// second-order runs; all other parameters at 1) gives one equation
//   [1, t_1(P), ..., t_n(P)] c = R(run)
// in the constants c. With as many runs as constants the square system is solved (LU with full
// pivoting); with more, in the least-squares sense (column-pivoted QR). The condition number
// (largest / smallest singular value) is reported. If the matrix is rank deficient, the null
// space (singular vectors of the zero singular values) says which constants the runs cannot
// separate: those are reported as not determined (NaN); the others are still unique and are
// given (minimum-norm solution).
//
// Derivatives at the design point (P = 1, Table 14) from the second-order form:
//   dR/dP_i        = A_i + 2 B_ii + sum_(j != i) B_ij
//   d2R/dP_i2      = 2 B_ii
//   d2R/dP_i dP_j  = B_ij
//
// Branches (issue 40). Each run records its discrete outcome (outcomes.hpp: which elements
// fractured, sheared, overrode or bottomed out, and when). A first-order run whose outcome
// differs from run 0's crossed a jump, and its A_i is not a sensitivity: its step is halved
// (branch_bisections times, one run each) to find the largest step on run 0's branch, and the
// effect within the branch, the jump and the values of P around the change are reported apart
// (BranchChange; sensitivity.md, sensitivity_branches.csv). A_i itself is left as the design
// defines it (the report's printed method).
//
// A design file says what each nondimensional parameter scales in the model, and the
// second-order study:
//   sensitivity: 1
//   factor: 1.2                         # first-order runs (default 1.2)
//   parameters:
//     - name: P7
//       description: anticlimber horizontal yield force
//       scale:                          # key *= value^power for every entry
//         - {key: elements.anticlimber.horizontal_yield_deflection, power: 1}
//   second_order:                       # optional
//     terms: [P6, P7, P6^2, P6*P7, P7^2]   # besides the constant A0
//     runs:                             # each: parameter -> value (the others 1.0)
//       - {P6: 0.8}
//       - {P6: 1.2, P7: 1.2}
// so a derived quantity (a yield force = slope x yield deflection) is varied through the
// inputs it is made of.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "railcrash/core/error.hpp"
#include "railcrash/model/yaml_file.hpp"
#include "railcrash/results/outcomes.hpp"
#include "railcrash/results/responses.hpp"
#include "railcrash/studies/batch.hpp"
#include "railcrash/studies/run_count.hpp"

namespace railcrash {

struct SensitivityParameter {
  std::string name;
  std::string description;
  std::vector<std::pair<std::string, double>> scales;  // (model key, power)
  std::vector<SourceLocation> scale_sources;           // where each scale entry is written (design or readings file)
};

/// A term of the second-order form: P_first (linear), P_first^2 (second == first) or
/// P_first P_second.
struct SensitivityTerm {
  std::string first, second;
  bool linear() const { return second.empty(); }
  bool square() const { return second == first; }
  std::string label() const;  // "P6", "P6^2", "P6*P7" (the design file's spelling)
  /// The term's value at the given parameter values (parameters not listed: 1.0).
  double value(const std::vector<std::pair<std::string, double>>& values) const;
};

/// Parameter name -> nondimensional value; parameters not listed are 1.0.
using SensitivityPoint = std::vector<std::pair<std::string, double>>;

struct SecondOrderDesign {
  std::vector<SensitivityTerm> terms;   // besides the constant
  std::vector<SensitivityPoint> runs;   // the second-order runs (Table 12)
  bool empty() const { return terms.empty() && runs.empty(); }
};

/// A study's published results, to compare a model's study with (the report's Tables 11, 13
/// and 15-17 for its design). In the design file:
///   reference:
///     source: text saying where the numbers come from
///     base: [R1, R2, R3]                   # run 0
///     first_order: {P1: [R1, R2, R3], ...} # each parameter's run at the design's factor
///     second_order: [[R1, R2, R3], ...]    # in the order of second_order.runs
///     ranking: {R1: [P7, P6, ...], R2: [...], R3: [...]}   # the printed rankings, best first
struct PublishedResults {
  std::string source;
  std::array<double, 3> base{};
  std::vector<std::pair<std::string, std::array<double, 3>>> first_order;  // parameter -> R1-R3
  std::vector<std::array<double, 3>> second_order;                         // per second-order run
  std::array<std::vector<std::string>, 3> ranking;                         // R1-R3, most important first
};

struct SensitivityDesign {
  double factor = 1.2;
  std::vector<SensitivityParameter> parameters;
  SecondOrderDesign second_order;
  std::optional<PublishedResults> reference;
};

/// Reads a design file (errors name the file and line).
SensitivityDesign load_design(const std::string& path);

/// The design file `sensitivity_design.yaml` beside the model file ("the report's design" for
/// models/report/final_two_car.yaml); InputError if there is none.
std::string default_design_path(const std::string& model_path);

struct SensitivityRun {
  SensitivityPoint variation;  // parameter -> value; empty for the base run
  std::string parameter;       // first-order runs: the parameter ("" for the base run); else "P6+P7"
  double factor = 1.0;         // first-order runs: its value
  bool ok = false;
  std::string message;
  Responses responses;
  double wall_seconds = 0.0;
  bool interrupted = false;    // stopped, or never started, because the study was interrupted
  OutcomeSignature outcomes;   // the run's discrete outcome (outcomes.hpp)
  IntegratorUsed integrator;   // the method the run used (batch.hpp): sensitivity.csv's integrator_used, euler_from_t
};

/// A first-order run whose discrete outcome differs from run 0's (issue 40): the step is bisected
/// towards 1 to find the largest step that stays on run 0's branch, so that the effect within the
/// branch and the jump where the branch changes are reported apart. Step s = value - 1.
struct BranchChange {
  std::size_t run = 0;              // index in SensitivityResult::runs
  std::string parameter;
  double nominal_value = 1.0;       // the run's value (the design's factor, or 1 +- h)
  double on_branch_value = 1.0;     // the value nearest nominal found on run 0's branch (1: none but run 0)
  double off_branch_value = 1.0;    // the value nearest 1 found off it (the branch changes in between)
  std::string off_branch_signature; // the outcome there (OutcomeSignature::text)
  std::array<double, 3> nominal_derivative{};  // A_i from the nominal step (across the change)
  std::array<double, 3> within_branch{};       // dR/dP from run 0 to on_branch_value (NaN: no step stayed on it)
  std::array<double, 3> jump{};                // R(off) - R(on) - within_branch (off - on): the jump across the change
  std::vector<SensitivityRun> bisection_runs;  // the extra runs, in the order they were made
  std::string note;                            // a bisection run failed, or the branch returned to run 0's
};

/// One run's data for a fit.
struct SensitivitySample {
  std::string label;
  SensitivityPoint point;
  std::array<double, 3> responses{};  // R1, R2, R3
};

struct SensitivityDerivative {
  std::string first, second;  // dR/dP_first (second empty), or the second derivative by P_first and P_second
  std::string label() const;  // "d/dP6", "d2/dP6^2", "d2/dP6dP7"
  std::array<double, 3> value{};
};

struct QuadraticFit {
  std::vector<SensitivityTerm> terms;             // besides the constant
  std::array<double, 3> constant{};               // A0 for R1-R3 (NaN if not determined)
  std::vector<std::array<double, 3>> coefficients;  // per term (NaN if not determined)
  std::vector<std::string> samples;               // labels of the runs used, in row order
  int equations = 0, unknowns = 0, rank = 0;
  double condition_number = 0.0;                  // largest / smallest singular value (inf if singular)
  double largest_residual = 0.0;                  // least squares: max |row . c - R|
  std::vector<std::string> undetermined;          // term labels ("1" = the constant) the runs cannot separate
  std::vector<SensitivityDerivative> derivatives; // at P = 1: first derivatives, then second (Table 14 order)
  bool determined() const { return unknowns > 0 && rank == unknowns; }
};

/// Fits R = A0 + sum c_k t_k(P) to the samples (see the header comment).
QuadraticFit fit_quadratic(const std::vector<SensitivityTerm>& terms, const std::vector<SensitivitySample>& samples);

struct SensitivityResult {
  SensitivityRun base;
  std::vector<SensitivityRun> runs;                // first-order, per parameter (central: +h then -h)
  std::vector<std::array<double, 3>> derivatives;  // A_i = dR1/dP, dR2/dP, dR3/dP per parameter run (NaN if a run failed)
  std::array<double, 3> constant{};                // A0 of equations (1)-(3)
  std::vector<SensitivityRun> second_order_runs;   // Table 12/13
  QuadraticFit fit;                                // empty terms: no second-order study
  std::string fit_note;                            // runs left out of the fit and why
  bool central = false;
  std::size_t runs_total = 0;     // runs the study has (base, first order, second order)
  std::size_t runs_finished = 0;  // runs that ended by themselves (ok or failed); fewer if interrupted
  bool interrupted = false;       // the stop flag rose: runs not finished are failed "not run" / "interrupted"
  std::vector<BranchChange> branch_changes;  // first-order runs off run 0's branch, bisected (issue 40)
  std::size_t bisection_runs = 0;            // extra runs the bisections made
};

struct SensitivityOptions {
  int jobs = 1;
  std::vector<std::string> settings;  // KEY=VALUE / KEY*=FACTOR applied to every run before the parameters' scaling
  double central_step = 0.0;         // > 0: central differences at 1 +- this
  std::vector<std::string> only;     // parameter names to run (empty: all); second-order runs and
                                     // terms are kept when all their parameters are among them
  bool second_order = true;          // run the design's second-order runs and fit
  double run_time_limit = 0.0;       // [s] wall time after which a run is stopped and reported failed (0: none)
  const std::atomic<bool>* stop = nullptr;  // raised (SIGINT/SIGTERM): runs in progress stop, no new run starts
  std::size_t max_runs = kDefaultMaxRuns;  // a study with more runs is refused before it starts (--max-runs; 0: no limit)
  int branch_bisections = 4;         // halvings of the step of a first-order run off run 0's branch (0: flag only)
  double branch_window = kBranchWindow;  // [s] outcomes this close form one group (outcomes.hpp)
  /// Called (one call at a time) as each run finishes: the run, its number (0 = base), runs done, runs in all.
  std::function<void(const SensitivityRun&, std::size_t, std::size_t, std::size_t)> progress;
};

/// Loads the model with every run's settings without running it, so that any input error (a
/// scale key the model does not have, a parameter whose model value is 0, a bad --set) stops the
/// study before its first run; the message names the design file's line of the scale entry.
/// Without every_run, the model is first loaded once with every parameter's factors at once
/// (what a reading study does for each of its many combinations), and run by run only if that fails.
void check_sensitivity_inputs(const CheckedYamlText& model_text, const std::string& model_path, const SensitivityDesign& design,
                              const SensitivityOptions& options, bool every_run);

/// The number of runs the study makes with these options (the base run, the first-order runs,
/// the second-order runs of the chosen parameters): the design's size, before any run.
std::size_t sensitivity_run_count(const SensitivityDesign& design, const SensitivityOptions& options);

SensitivityResult run_sensitivity(const std::string& model_path, const SensitivityDesign& design,
                                  const SensitivityOptions& options);

/// Writes DIR/sensitivity.md (all tables, shaped like the report's Tables 11-17) and the CSV files
/// DIR/sensitivity.csv (runs), sensitivity_first_order.csv (A0, A_i), sensitivity_second_order.csv
/// (fitted constants), sensitivity_derivatives.csv (Table 14), sensitivity_ranking.csv (Tables
/// 15-17); returns the Markdown.
std::string write_sensitivity(const SensitivityResult& result, const SensitivityDesign& design, const std::string& directory);

}  // namespace railcrash
