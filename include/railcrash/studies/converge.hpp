// Convergence study of one model (`railcrash converge`): how the error in crash quantities
// falls with the cost of a run, for both integrators.
//
//   1. Reference: IDA at a tight tolerance (default rtol 1e-9; when that run fails, it is
//      retried ten times looser, as long as it stays ten times tighter than every IDA run).
//   2. Explicit Euler at steps dt_k = dt_0 / 2^k, k = 0 .. N-1, where dt_0 is a safety factor
//      (default 0.8) times the stability limit of the model's elements at the start
//      (explicit_stability_limit, as `railcrash check` prints it), rounded
//      down to a whole fraction of the output interval so that every run samples at the same
//      times, and lowered further if the penalty joints at that step make it unstable.
//   3. IDA at each requested relative tolerance (a model that sets atol has it scaled with rtol).
// A run that fails (divergence, solver failure, over the time limit) has no values; its row
// says why, and the fits and the cost comparison leave it out.
// For every run and quantity: the value, and its error relative to the reference,
//   e = |Q - Q_ref| / |Q_ref|            (scalar quantities; undefined when Q_ref = 0)
// and the cost: wall time (integrator set-up, i.e. consistent start and Euler's stability
// estimate, plus integration), steps, residual (Euler: force) and Jacobian evaluations.
//
// Quantities (names as on the command line):
//   max_crush               largest crush [length]: R1's crush measure when the model has a
//                           responses section with crush gauges or `crush: anticlimber`, else the
//                           largest `crush` of crush_spring and `horizontal_deformation` of
//                           anticlimber elements
//   peak_anticlimber_force  largest |horizontal_force| of the anticlimber elements [force]
//   peak_coupler_force      largest |normal_force| of coupler_end and |horizontal_force| of
//                           coupling elements [force] (draft gears: name them as element.NAME.force)
//   R1, R2                  the report's responses (responses.hpp)
//   displacement_rms        RMS over the reference's output times and over all bodies of the
//                           x and y displacement differences to the reference (the run's history
//                           interpolated linearly), divided by the reference's largest |x or y
//                           displacement| from the start: its "value" is the RMS [length], its
//                           error the normalised RMS
//   element.NAME.OUTPUT     largest |value| of one element output column (as in summary.json peaks)
//   body.NAME.x|y|theta     displacement from the start at the end of the run; error relative
//                           to the reference's largest |displacement| of that coordinate
// Peaks are taken over the output samples, as in summary.json (--output-interval for finer ones). A quantity that does not apply
// to the model (no anticlimber, no responses, ...) is reported as not applicable with the
// reason, never as zero.
//
// Analysis: observed orders are least-squares slopes of log(error) against log(dt) (Euler,
// first order expected) and against log(wall time) (both methods; IDA also against log(rtol)).
// Cost at equal accuracy: for each error level of the headline quantity, the wall time at
// which each method reaches it for good: from the loosest setting (dt, rtol) at which that run
// and every tighter run of the method meet the level, interpolated log-log between that run and
// the next looser one (which misses it); when the tightest run misses it, extrapolated along the method's
// fitted error-versus-time line (marked as such), and when even its cheapest run is more
// accurate, bounded by that run's time (marked "<="); Euler time / IDA time is printed with
// the same marks.
//
// Runs are independent and may go in parallel (jobs), but wall times measured under parallel
// load are noisier (and longer: two cores shared); the default is one job for clean timing.
#pragma once

#include <atomic>
#include <functional>
#include <optional>
#include <limits>
#include <string>
#include <vector>

#include "railcrash/results/responses.hpp"
#include "railcrash/solver/integrator.hpp"

namespace railcrash {

struct ConvergeOptions {
  std::vector<std::string> quantities;        // empty: the defaults (default_quantities())
  int euler_runs = 5;                         // dt_0 and N - 1 halvings; 0: no Euler runs
  double euler_safety = 0.8;                  // dt_0 = safety x stability limit (0 < safety < 1)
  double euler_first_step = 0.0;              // [time] > 0: dt_0 given instead (must be stable)
  std::vector<double> rtols{1e-3, 1e-4, 1e-5, 1e-6};  // IDA runs
  double reference_rtol = 1e-9;               // IDA reference
  std::optional<double> t_end;                // [time] default: the model's
  std::optional<double> output_interval;      // [time] default: the model's
  std::vector<std::string> settings;          // KEY=VALUE / KEY*=FACTOR model overrides
  int jobs = 1;
  double run_time_limit = 0.0;                // [s] wall time after which a run is stopped (reported failed); 0: none.
                                              // It acts where the integrator checks its stop flag: Euler every
                                              // step, IDA between output times (not inside one IDASolve call)
  std::string headline;                       // quantity for the cost ratio; "" = first applicable
  std::vector<double> levels{1e-2, 1e-3};     // relative error levels for the cost ratio
};

/// The default quantity list, in order.
std::vector<std::string> default_quantities();

struct ConvergeQuantity {
  enum class Kind {
    MaxCrush, PeakAnticlimberForce, PeakCouplerForce, R1, R2, DisplacementRms, ElementPeak, BodyDisplacement,
    EventTime,          // event.NAME[:TEXT]: time of the element's first event (whose description contains TEXT)
    PeakAcceleration    // acceleration.BODY: peak CFC-60 filtered acceleration magnitude of the body
  };
  std::string name;
  std::string description;     // what it measures, with its unit
  Kind kind = Kind::MaxCrush;
  bool applicable = true;
  std::string note;            // why not applicable
  std::vector<int> columns;    // element output columns (DaeSystem::outputs) it takes the peak of
  bool signed_peak = false;    // largest value (crush) rather than largest |value|
  bool from_responses = false; // max_crush from the responses section
  int body = -1;               // body quantities: body index and component (0 x, 1 y, 2 theta)
  int component = 0;
  std::string event_element;   // EventTime: the element's name and a text its event's description contains
  std::string event_text;      // ("" = any event of the element)
};

/// One run of the study and its figures.
struct ConvergeRun {
  std::string method;          // "reference", "euler" or "ida"
  double step = 0.0;           // euler: [time]
  double rtol = 0.0;           // ida and reference
  bool ok = false;
  std::string message;
  double wall_seconds = 0.0;   // integrator set-up + integration
  RunStatistics stats;
  std::vector<double> values;  // per quantity (NaN: not applicable or failed)
  std::vector<double> errors;  // per quantity, relative to the reference (NaN: undefined)

  // What the values are made of (kept for the analysis).
  std::vector<double> times;          // [time] output samples
  std::vector<double> displacements;  // per sample, per body: x, y, theta minus their start values
  std::vector<double> peak_abs;       // per element output column: largest |value|
  std::vector<double> peak_max;       // per element output column: largest value
  bool has_responses = false;
  Responses responses;
  std::vector<EventRecord> events;           // every committed mode change, in order
  std::vector<double> peak_acceleration;     // per body: peak CFC-60 acceleration magnitude [g]
                                             // (filled when a PeakAcceleration quantity is asked for)
};

struct ConvergeFit {
  double slope = 0.0;  // NaN when fewer than two usable points
  int points = 0;
};

struct ConvergeLevel {
  double level = 0.0;                    // relative error
  double euler_seconds = 0.0, ida_seconds = 0.0;  // NaN: not available
  std::string euler_how, ida_how;        // "interpolated", "extrapolated", "<=", "not reached", "no runs"
};

struct ConvergeResult {
  std::string model_path;
  std::string model_name;
  std::string length_unit, force_unit;
  double t_end = 0.0;                    // [time]
  double output_interval = 0.0;          // [time]
  double element_stability_limit = 0.0;  // [time] Euler's, elements alone (0: dt_0 given)
  double stability_limit = 0.0;          // [time] Euler's at dt_0, penalty joints included
  int jobs = 1;
  std::vector<ConvergeQuantity> quantities;
  int headline = -1;                     // index into quantities (-1: none applicable)
  ConvergeRun reference;
  std::string reference_note;            // when the reference had to be retried at a looser tolerance
  std::vector<ConvergeRun> euler;        // in order of decreasing step
  std::vector<ConvergeRun> ida;          // in order of the requested tolerances
  // Per quantity:
  std::vector<ConvergeFit> euler_order;        // log e vs log dt
  std::vector<ConvergeFit> euler_time_slope;   // log e vs log wall time
  std::vector<ConvergeFit> ida_rtol_slope;     // log e vs log rtol
  std::vector<ConvergeFit> ida_time_slope;     // log e vs log wall time
  std::vector<ConvergeLevel> levels;           // headline quantity at equal accuracy
  double total_seconds = 0.0;
  std::size_t runs_total = 0;     // the reference and the Euler and IDA runs planned
  std::size_t runs_finished = 0;  // of those, the runs that ended by themselves (fewer if interrupted)
  bool interrupted = false;       // the stop flag rose (SIGINT/SIGTERM): the other runs are failed "not run"
};

/// What the study will do, worked out before it runs (the caller may print it).
struct ConvergePlan {
  std::string model_path;
  ConvergeOptions options;
  std::vector<ConvergeQuantity> quantities;
  int headline = -1;
  double t_end = 0.0, output_interval = 0.0;  // [time]
  double model_rtol = 0.0;                    // the model's own rtol (with the user's settings)
  std::optional<double> model_atol;           // [the model file's length unit] its atol, if it sets one
  double element_stability_limit = 0.0;       // [time] Euler's limit from the elements alone, at the start
  double stability_limit = 0.0;               // [time] Euler's limit at dt_0, penalty joints included
  std::vector<double> euler_steps;            // [time]
  double euler_seconds_per_step = 0.0;        // [s] measured on a short Euler run at dt_0
  double euler_estimate_seconds = 0.0;        // [s] all Euler runs, one job
  std::string length_unit, force_unit, model_name;
};

/// Loads the model, resolves and checks the quantities (InputError for unknown names), finds
/// dt_0 and times a short Euler run to estimate the cost of the Euler runs.
ConvergePlan plan_convergence(const std::string& model_path, const ConvergeOptions& options);

/// Runs the plan (reference, Euler, IDA) and analyses it. `on_run` (may be empty) is called,
/// one call at a time, as each run finishes. Runs stop early when *stop becomes true.
ConvergeResult run_convergence(const ConvergePlan& plan, const std::function<void(const ConvergeRun&)>& on_run = {},
                               const std::atomic<bool>* stop = nullptr);

/// Least-squares slope of log(y) against log(x) over the points where both are positive and finite.
ConvergeFit log_log_slope(const std::vector<double>& x, const std::vector<double>& y);

/// Wall time at which a method's runs reach a relative error level in one quantity, and how it
/// was found ("interpolated", "extrapolated", "<=", "not reached", "no runs"): see the header's
/// "Cost at equal accuracy".
struct TimeAtLevel {
  double seconds = std::numeric_limits<double>::quiet_NaN();
  std::string how;
};
TimeAtLevel time_at_level(const std::vector<ConvergeRun>& runs, std::size_t quantity, double level);

/// The summary as Markdown: run table, orders, cost at equal accuracy.
std::string convergence_markdown(const ConvergeResult& result);

/// Writes DIR/converge.csv (one row per run), DIR/converge.svg (headline error versus wall
/// time, log-log, one series per method) and DIR/converge.md; returns the Markdown.
std::string write_convergence(const ConvergeResult& result, const std::string& directory);

}  // namespace railcrash
