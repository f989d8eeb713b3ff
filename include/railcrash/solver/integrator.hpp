// What both integrators share: run statistics, the observer that receives output samples,
// and the outcome of a run. Integrators see a DaeSystem, never an element.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "railcrash/model/run_spec.hpp"  // the methods' names
#include "railcrash/solver/chatter_guard.hpp"
#include "railcrash/solver/dae_system.hpp"
#include "railcrash/solver/events.hpp"

namespace railcrash {

/// The phases a run's wall time is split into when it is timed (`railcrash run --timings`;
/// summary.json's stats.seconds). Each is exclusive: a phase entered inside another (a restart
/// while events are handled, a sample written at an event, a residual of Euler's re-sweep after
/// a mode change) counts for itself alone, so the phases add up to the run's wall time.
enum class Phase : int {
  Other,        // the integrator's own work: IDA's vector operations, error test, step and order
                // choice, interpolation for events; Euler's update; the run loop's checks
  Start,        // start(): initial conditions, static settle, integrator set-up
  Residual,     // ida: IDA's residual calls; euler: the force sweep (forces, roots, outputs)
  Jacobian,     // ida: Jacobian values
  LinearSetup,  // ida: KLU factorizations
  LinearSolve,  // ida: KLU solves
  StepSweep,    // ida: each step's sweep of energy rates, roots and step outputs
  Events,       // finding, locating and committing mode changes
  Restarts,     // ida: consistent rates after a mode change and the integrator's restart
  Output,       // output samples (interpolation, rows, files) and observers' per-step tracking
  kCount
};
constexpr int kPhaseCount = static_cast<int>(Phase::kCount);
/// summary.json's names of the phases, in Phase's order.
constexpr const char* phase_name(Phase phase) {
  constexpr const char* kNames[] = {"other",        "start",     "residual", "jacobian", "linear_setup",
                                    "linear_solve", "step_sweep", "events",   "restarts", "output"};
  static_assert(sizeof kNames / sizeof kNames[0] == static_cast<std::size_t>(Phase::kCount), "a name per phase");
  return static_cast<int>(phase) >= 0 && phase < Phase::kCount ? kNames[static_cast<int>(phase)] : "?";
}

/// Exclusive wall time per phase: enter() closes the running phase's interval and opens the
/// next (one clock reading per change). Off unless start()ed, when Scope does nothing.
class PhaseClock {
 public:
  void start();
  bool on() const { return on_; }
  /// Enters `phase`; returns the phase it leaves (for Scope to return to).
  Phase enter(Phase phase);
  /// Closes the running interval; the seconds per phase so far.
  const std::array<double, kPhaseCount>& stop();

  /// The scope's time counts for `phase` (nothing when clock is null or off).
  class Scope {
   public:
    Scope(PhaseClock* clock, Phase phase) : clock_(clock != nullptr && clock->on() ? clock : nullptr) {
      if (clock_ != nullptr) previous_ = clock_->enter(phase);
    }
    ~Scope() {
      if (clock_ != nullptr) clock_->enter(previous_);
    }
    Scope(const Scope&) = delete;
    Scope& operator=(const Scope&) = delete;

   private:
    PhaseClock* clock_;
    Phase previous_ = Phase::Other;
  };

 private:
  bool on_ = false;
  Phase current_ = Phase::Other;
  std::chrono::steady_clock::time_point since_;
  std::array<double, kPhaseCount> seconds_{};  // [s]
};

struct RunStatistics {
  long steps = 0;
  long residual_evaluations = 0;   // ida: residual calls; euler: force evaluations
  long jacobian_evaluations = 0;   // ida: the elements' Jacobians evaluated
  long linear_setups = 0;          // ida: Newton matrices factored (a Jacobian evaluated or kept: IdaSettings::jacobian_kept_steps)
  long nonlinear_iterations = 0;
  long error_test_failures = 0;
  long nonlinear_convergence_failures = 0;
  long events = 0;
  long root_returns = 0;       // ida: mode changes located within a step (summary: located_mode_changes)
  long reinitializations = 0;  // ida: restarts (a mode change the step could not absorb); euler: mode changes
  double wall_seconds = 0.0;
  double last_step = 0.0;          // [time]
  double stability_limit = 0.0;    // euler: [time] estimated largest stable step
  double assembly_correction = 0.0;  // [length] largest move of the initial position assembly
  long settling_steps = 0;           // static equilibrium: pseudo-time steps
  double settling_displacement = 0.0;  // [length] static equilibrium: largest move
  long factor_nonzeros = 0;          // ida: entries KLU stores: L, U and the off-diagonal blocks (last factorization)
  std::string factor_ordering;       // ida: KLU's fill-reducing ordering, "AMD" or "COLAMD" (the one with fewer entries)
  double handed_over_at = -1.0;      // [time] integrator auto: when IDA handed the run to Euler (-1: it did not)
  double handed_back_at = -1.0;      // [time] integrator auto: when IDA took the run back from Euler (-1: it did not)
  double euler_step = 0.0;           // [time] euler, or auto's Euler part: its step (0: Euler took none)
  double newton_iterations_raised_at = -1.0;  // [time] ida: where a Newton failure raised IDA's iterations per step from 4 (-1: never)
  double bdf_order_held_at = -1.0;  // [time] ida: where the energy the integration created held IDA's BDF order to 2 (-1: never)
  // ida, relative position tolerance: how far the model sits from its origin, in its own size
  // (the relative form's length scale, or its farthest body coordinate at t = 0, over the box
  // around its bodies and ground points); 0 under the absolute form (README "Position tolerances").
  double origin_distance_in_sizes = 0.0;
  std::string hand_over_reason;      // integrator auto: why it did, or why IDA kept the run ("" before the run ends)
  bool phases_timed = false;         // the run was timed by phase (Integrator::time_phases)
  std::array<double, kPhaseCount> phase_seconds{};  // [s] wall time per Phase, when timed
};

/// The method a run of integrator ida or auto used, from its statistics: "ida", "ida+euler"
/// (IDA handed the run to Euler) or "ida+euler+ida" (and took it back).
inline const char* ida_or_auto_method(const RunStatistics& s) {
  return s.handed_back_at >= 0.0   ? kIdaEulerIdaMethod
         : s.handed_over_at >= 0.0 ? kIdaThenEulerMethod
                                   : integrator_name(IntegratorKind::Ida);
}

/// Which element outputs a RunObserver::step() call holds values of at its state: those of the
/// elements the observer's step columns belong to (RunObserver::mark_step_columns: all of them
/// when any observer asks for every column), or one element's alone (either side of that
/// element's mode change located inside a step, where only its outputs are evaluated: every
/// output at every such event made a train's cost grow as N^2). The other columns hold values
/// from an earlier evaluation and must not be read.
struct FreshOutputs {
  int begin = 0;                               // first evaluated column of DaeSystem::outputs
  int end = std::numeric_limits<int>::max();   // one past the last
  /// Null: every column in [begin, end) is fresh; else only those marked nonzero here (one
  /// entry per column of DaeSystem::outputs). Never set when an observer asked for every column.
  const char* marked = nullptr;
  bool has(int column) const { return column >= begin && column < end && (marked == nullptr || marked[column] != 0); }
  /// Whether every column of a sum over several outputs is fresh.
  bool has_all(const std::vector<int>& columns) const {
    for (const int column : columns)
      if (!has(column)) return false;
    return true;
  }
  /// One past the last fresh column of an array of `count` columns (with `marked` set, the
  /// columns before it that are fresh are those has() names).
  std::size_t end_within(std::size_t count) const { return std::min(count, static_cast<std::size_t>(end)); }
};

/// Receives the state at every output time (t = 0 included).
class RunObserver {
 public:
  virtual ~RunObserver() = default;
  /// lambda: constraint multipliers (ida) or penalty forces (euler); quadratures as in DaeSystem;
  /// outputs: the element outputs at the sample (DaeSystem::outputs), evaluated once for all
  /// observers.
  virtual void sample(double t, const double* y, const double* lambda, const double* quadratures, const double* outputs) = 0;
  /// True when the observer takes the generalized forces at each sample (sample_with_forces):
  /// the run loop then evaluates them in the same sweep over the elements as the outputs.
  virtual bool wants_sample_forces() const { return false; }
  /// sample() with the generalized forces at the sample as well, for an observer that
  /// wants_sample_forces(): `forces` (DaeSystem::body_unknowns()) is what
  /// DaeSystem::generalized_forces(t, q, v, forces, nullptr, nullptr, lambda) gives (gravity,
  /// loads, force elements, joint friction at lambda; no constraint reactions), bit for bit.
  virtual void sample_with_forces(double t, const double* y, const double* lambda, const double* quadratures,
                                  const double* outputs, const double* /*forces*/) {
    sample(t, y, lambda, quadratures, outputs);
  }
  /// A committed mode change (contact, yield, rupture, ...); y is the state at that instant.
  virtual void event(const EventRecord& /*record*/, const double* /*y*/) {}
  /// The state at the end of every accepted step and on both sides of every committed mode
  /// change (before it: the old modes; after it: the new ones), whatever the output times:
  /// for extrema (peaks, crush, responses) that must not depend on the output interval.
  /// Nothing is written from it. lambda as in sample(); outputs: the element outputs there
  /// (DaeSystem::outputs), evaluated once for all observers, but only the columns `fresh` has:
  /// an extremum of a quantity computed from y, or from fresh columns alone, is taken here;
  /// one that also needs other columns (a sum over several elements' outputs) evaluates them
  /// at y itself (as car_crush_at in results.hpp does), or is not taken.
  virtual void step(double /*t*/, const double* /*y*/, const double* /*lambda*/, const double* /*outputs*/,
                    const FreshOutputs& /*fresh*/) {}
  /// True when step() does something: only then does the run loop evaluate the outputs per step.
  virtual bool observes_steps() const { return false; }
  /// Marks (sets to 1) the columns of DaeSystem::outputs that step() reads; `columns` has one
  /// entry per column. Asked once at the start of a run when observes_steps(). Per step, the
  /// run loop evaluates only the outputs of the elements whose columns some observer marked
  /// (an element's outputs come from one evaluation); every row still has all of them. The
  /// default marks every column: an observer that tracks the extremes of all outputs (the
  /// summary's peaks) keeps it; one that reads a few columns names them, so that the other
  /// elements' outputs are not computed at every step.
  virtual void mark_step_columns(std::vector<char>& columns) const { std::fill(columns.begin(), columns.end(), char{1}); }
  /// Why the observer cannot go on (a failed write: the OS's reason), "" while it can; the
  /// run loop stops at once when it is not empty.
  virtual std::string failure() const { return ""; }
};

struct RunOutcome {
  bool ok = false;
  std::string message;
  double t_reached = 0.0;
  RunStatistics stats;
  std::vector<double> y;            // final state
  std::vector<double> quadratures;  // final quadratures
  EnergyState initial_energy;
  EnergyState final_energy;
  double max_constraint_residual = 0.0;  // largest |Phi| over the output samples [length]
  double most_energy_turned_over = 0.0;  // largest DaeSystem::work_balance turned_over at the output samples [energy]
  std::vector<EventRecord> events;       // every committed mode change, in order
};

/// What every integrator takes from the run's simulation settings (SimulationSettings,
/// model/run_spec.hpp) beside its own: given to it explicitly, never read through the model.
struct CommonRunSettings {
  double t_end = 1.0;               // [time] the run's end in its settings: the time scale of the look-ahead off a
                                    // mode boundary (ModeTracker::set_run_end), Euler's step count check and fallback step
  bool static_equilibrium = false;  // settle the bodies under gravity and loads at t = 0 first (prepare_start)
};

/// The run loop both integrators share (Drake's IntegrateTo over DoStep): run() starts the
/// integrator, forwards its mode changes to the observer, samples the state at the output
/// times, checks after every accepted step that the state is finite, obeys the stop flag and
/// the step limit, and fills the outcome and the statistics, once for every integrator. An
/// integrator implements only its own steps: start(), advance() (one step) and the state at
/// a time (state_at; dense output, or the state at the end of the last step).
///
/// The failure contract: a run is ok only when it reached t_end; otherwise its message says
/// why (interrupted, step limit, solver failure, a non-finite state naming the body
/// coordinate or element multiplier and t). A failed run ends at its last output sample, the
/// last good state the observer (and the files) received: a non-finite state is never sampled.
/// An observer that cannot go on (RunObserver::failure, e.g. a failed write) stops the run at
/// the sample where it says so.
class Integrator {
 public:
  virtual ~Integrator() = default;
  virtual const char* name() const = 0;
  /// Integrates from 0 to t_end, sampling every output_interval; stops early (ok = false,
  /// message says why) on failure or when *stop becomes true. Input errors throw InputError.
  RunOutcome run(double t_end, double output_interval, RunObserver& observer, const std::atomic<bool>* stop = nullptr);
  /// How many changes of one element in a row at one instant stop a run (chatter_guard.hpp;
  /// default ChatterGuard::kLimit). Tests set a smaller one.
  void set_chatter_limit(long changes) { chatter_limit_ = changes; }
  /// Whether run() splits its wall time by Phase (RunStatistics::phase_seconds). Off by
  /// default: two clock readings per phase entered cost 0-2 % of a run (bench/timings_overhead.py).
  void time_phases(bool on) { time_phases_ = on; }

 protected:
  /// A failure of the integration itself (not of the input): becomes the outcome's message.
  class StepFailure : public std::runtime_error {
   public:
    using std::runtime_error::runtime_error;
  };

  explicit Integrator(DaeSystem& system) : system_(system), modes_(system), locator_(system) {}

  // ---- per-integrator steps ----
  /// Prepares the state at t = 0 (reporting start events through report_events).
  virtual void start(double t_end) = 0;
  /// Takes one step towards t_end and returns the time reached. Dense integrators call
  /// sample_up_to(t_event) before reporting a mode change at t_event. Throws StepFailure.
  virtual double advance(double t_end) = 0;
  /// True when state_at gives the state at any time within the last step (samples fall on
  /// the output times); false: samples are taken at the end of the step that passes one.
  virtual bool dense_output() const = 0;
  /// The state y (q, v, multipliers) and the quadratures at t (a dense integrator: within
  /// its last step; otherwise the current state).
  virtual void state_at(double t, std::vector<double>& y, std::vector<double>& quadratures) = 0;
  /// The current state (at the time advance returned), for the finiteness check of every step.
  virtual const double* current_state() const = 0;
  /// The state and quadratures a run that reached t_end ends with.
  virtual void final_state(std::vector<double>& y, std::vector<double>& quadratures) = 0;
  /// Energy figures of a state (Euler adds its penalty springs).
  virtual EnergyState energy(const double* y, const double* quadratures) const { return system_.energy(y, quadratures); }
  /// Advice after "stopped at t = ... after --max-steps N steps": what the step was, what to do.
  virtual std::string step_limit_advice(double t_end) const = 0;
  /// What a non-finite state means for this integrator ("explicit Euler diverged").
  virtual std::string divergence_phrase() const = 0;
  /// Extra advice after a non-finite state; last_good is the last sampled state (t_last_good).
  virtual std::string divergence_advice(const std::vector<double>& /*last_good*/, double /*t_last_good*/) const { return ""; }
  /// Largest number of advance() calls in one run.
  virtual long max_steps() const = 0;
  /// Called once at the end of every run (also after a failure): counters into stats().
  virtual void finish() {}
  /// The element outputs at current_state() in the present modes when the integrator already
  /// computed them (Euler's one sweep per step, IDA's sweep of the step's roots), else null:
  /// deliver_step evaluates them.
  virtual const double* current_outputs() const { return nullptr; }
  /// Asked after every accepted step (t: its end, y: current_state()) by a run loop that
  /// may go on with another integrator (integrator: auto): the integrator that takes the rest of
  /// the run from this state, or null to go on with this one. The run loop then calls this
  /// one's finish(), and the successor goes on with the run's samples, statistics and events;
  /// it must be ready to advance() from t (its start() is not called).
  virtual std::unique_ptr<Integrator> hand_over(double /*t*/, const double* /*y*/) { return nullptr; }
  /// Called on the successor once it holds the run (its statistics among it).
  virtual void continue_from_hand_over() {}
  /// Asked of a successor after every accepted step (t: its end, y: current_state()), before
  /// the step is delivered to the observers or sampled (sample_here: the step's end will be an
  /// output sample): whether the integrator that began the run takes it back from this state
  /// (integrator auto: Euler whose run has turned out less accurate than the accuracy warnings
  /// allow). The run loop then calls this one's finish() and the first integrator's resume(),
  /// and the step's end is delivered and sampled from the state resume() left.
  virtual bool returns_run(double /*t*/, const double* /*y*/, bool /*sample_here*/) { return false; }
  /// On the integrator that began the run, once it holds the run again (returns_run): goes on
  /// from the successor's state y and quadratures at t; must be ready to advance() from t.
  /// Throws StepFailure when it cannot.
  virtual void resume(double /*t*/, std::vector<double> /*y*/, const std::vector<double>& /*quadratures*/) {
    throw StepFailure("this integrator cannot take a run back");
  }
  /// Asked when advance() failed with a StepFailure (failure: its message) by the run loop: the
  /// integrator that takes the rest of the run from this one's last good state (integrator:
  /// auto hands IDA's failed run to Euler), or null to end the run failed. *t: the time of
  /// that state, where the successor starts. As hand_over otherwise.
  virtual std::unique_ptr<Integrator> rescue(const std::string& /*failure*/, double* /*t*/) { return nullptr; }

  // ---- for the integrators: what the run loop owns ----
  /// Forwards committed mode changes (the state at that instant: y) to the observer and the
  /// outcome; the observer's step() then sees y in the new modes.
  /// element: the one element that changed (its outputs are evaluated afresh for step(); the
  /// others keep their values of the last step: they did not change mode), -1: any number.
  void report_events(const std::vector<EventRecord>& events, const double* y, int element = -1);
  /// Why the run stopped when the chatter guard tripped on `last` (names the element and its line).
  std::string chatter_message(const EventRecord& last) const;
  /// The state at t (y: q, v, multipliers) in the modes before a mode change about to be
  /// committed there, for the observer's step() (a rupture's last force, say).
  void observe_before_event(double t, const double* y, int element = -1);
  /// Dense output: samples every output time up to t_limit not sampled yet.
  void sample_up_to(double t_limit);
  RunStatistics& stats() { return outcome_.stats; }
  /// The event layer (events.hpp), owned here for the integrator's steps: the element modes'
  /// bookkeeping (every commit of a mode change goes through it) and the crossings' locator.
  ModeTracker& mode_tracker() { return modes_; }
  EventLocator& event_locator() { return locator_; }
  /// The run's phase clock when it is timed, else null (for PhaseClock::Scope).
  PhaseClock* phase_clock() { return phase_clock_.on() ? &phase_clock_ : nullptr; }
  /// Whether the observer takes every step's element outputs (an integrator that can compute
  /// them with other work hands them over through current_outputs()).
  bool step_outputs_wanted() const { return observe_steps_; }
  /// Per element of the model, nonzero when some observer's step() reads one of its outputs
  /// (RunObserver::mark_step_columns); null when every element's are read (or none, when
  /// !step_outputs_wanted()). An integrator that hands over current_outputs() need compute
  /// only these elements' outputs per step (DaeSystem::SweepExtras::output_elements).
  const char* step_output_elements() const { return observe_steps_ && !step_elements_.empty() ? step_elements_.data() : nullptr; }
  /// The run's energy figures at t = 0 (a successor's own check of its accuracy, returns_run).
  const EnergyState& run_initial_energy() const { return outcome_.initial_energy; }
  /// The state and quadratures at t for a successor (hand_over): as state_at gives them.
  void state_for_successor(double t, std::vector<double>& y, std::vector<double>& quadratures) { state_at(t, y, quadratures); }

  DaeSystem& system_;

 private:
  /// Moves the run in progress (outcome, observer, output times, last samples, phase clock)
  /// from `previous` into this integrator, which goes on with it (hand_over).
  void take_run_from(Integrator& previous);
  void deliver_sample(double t);
  /// Passes the state y at t, with its element outputs, to the observer's step().
  void deliver_step(double t, const double* y, int element = -1);
  double next_output_time() const;
  /// Names the first non-finite entry of y ("" when all are finite).
  std::string non_finite_entry(const double* y) const;

  ModeTracker modes_;
  EventLocator locator_;

  // State of the run in progress.
  RunOutcome outcome_;
  RunObserver* observer_ = nullptr;
  double t_end_ = 0.0;
  ChatterGuard chatter_{1.0};  // the run's events, against an element chattering at one instant (reset by run)
  long chatter_limit_ = ChatterGuard::kLimit;
  double output_interval_ = 0.0;
  long output_index_ = 1;       // next output time: output_index_ * output_interval_
  double t_sampled_ = 0.0;      // last sample
  std::vector<double> sample_y_, sample_quadratures_;
  std::vector<double> sample_outputs_;      // element outputs at the sample
  std::vector<double> sample_forces_;       // generalized forces at the sample, when the observer wants them
  bool observe_sample_forces_ = false;      // the observer wants_sample_forces()
  std::vector<double> constraint_scratch_;  // work space of the per-sample constraint residual
  double last_sample_residual_ = 0.0;       // [length] |Phi| at the last sample
  std::vector<double> last_sample_y_, last_sample_quadratures_;
  bool observe_steps_ = false;       // the observer wants step()
  bool time_phases_ = false;         // time_phases()
  PhaseClock phase_clock_;
  std::vector<double> step_outputs_;  // element outputs at the last step
  /// What the observer's step() reads, when it is not every element's outputs (else empty):
  /// per element, whether its outputs are evaluated per step (step_output_elements()), and per
  /// column of DaeSystem::outputs, whether it belongs to such an element (FreshOutputs::marked).
  std::vector<char> step_elements_, step_columns_;
  /// Sets step_elements_ and step_columns_ from the observer's mark_step_columns.
  void choose_step_outputs();
};

/// Largest |Phi| tracker shared by the integrators.
double max_abs(const std::vector<double>& values);

}  // namespace railcrash
