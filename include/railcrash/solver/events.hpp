// Events as their own layer (issue 37 item 5): what every integrator needs to find, locate and
// commit mode changes, written once against a small step interpolant instead of inside each
// integrator.
//
// * StepInterpolant: the solution over the last step [t0, t1] as an integrator gives it: the
//   whole state y(t), a few unknowns of it (an element's, cheaply), and the rates y'(t). IDA's
//   comes from its interpolating polynomial (IDAGetDky); Euler's knows only the step's end.
// * ModeTracker: the run's bookkeeping of element modes across steps: the root functions at
//   the step's start and end, the roots resting on their mode's boundary (carried as +0 until
//   clearly below zero), and which elements changed mode in the current step, how often and
//   when; and every write of the element modes and histories (ElementStates): each commit of a
//   mode change (the elements' commit, with the event's record), the reset to the start modes
//   and the return to a snapshot (initial_conditions.cpp's start and settle, Euler's restart of
//   a second run, all write through it). The modes' storage sits beside the DaeSystem (one per
//   system, shared by every tracker of it), which only reads it: the tracker is its one writer.
// * EventLocator: the queue of crossings of the current step in time order, the location of a
//   root that fell through zero (Illinois on the interpolant, only the element's unknowns
//   interpolated), and the nudge that moves a located time forward until the interpolated
//   state is at or below zero.
//
// Roots are positive inside their mode (element.hpp): a fall through zero leaves the mode.
//
// What an integrator still does itself: take its step, give its StepInterpolant and answer an
// EventHandler (event_loop.hpp: commit_crossings, the loop over a step's crossings): whether it
// goes on across a change (IDA's lag test) and its restart; Euler's steps are known at their
// end alone, so the loop commits there. The integrators ask the DaeSystem, never an element,
// and change the element modes only through a ModeTracker.
#pragma once

#include <vector>

#include "railcrash/solver/dae_system.hpp"

namespace railcrash {

/// The solution over one step [t0, t1] of an integrator.
class StepInterpolant {
 public:
  virtual ~StepInterpolant() = default;
  /// Start and end of the step [time].
  virtual double t0() const = 0;
  virtual double t1() const = 0;
  /// True when the state is known anywhere in [t0, t1] (events are located inside the step);
  /// false when it is known at t1 alone (events are committed at the step's end).
  virtual bool dense() const = 0;
  /// The whole state y(t) (DaeSystem::size() entries). The pointer stays valid until the next
  /// call of state_at.
  virtual const double* state_at(double t) = 0;
  /// Only the listed unknowns of y(t), into their places in y (the others are left alone):
  /// an element's few unknowns, at a cost independent of the model's size.
  virtual void unknowns_at(const std::vector<int>& unknowns, double t, double* y) = 0;
  /// The rates y'(t) (DaeSystem::size() entries).
  virtual void rates_at(double t, double* yp) = 0;
};

/// A root that fell through zero within the current step.
struct Crossing {
  double t = 0.0;  // [time] located (or the step's end until located)
  int element = 0;
  int local = 0;       // the root's index within its element
  int generation = 0;  // the element's mode changes in this step when it was found
  int direction = -1;  // -1: fell through zero; +1: rose through it (seen only on a step known at its end alone)
};

/// The element modes' bookkeeping of a run in progress (see the file's comment).
class ModeTracker {
 public:
  /// unknown_floor: per unknown of y, the magnitude below which its rounding counts as that
  /// floor (IDA's absolute tolerances) for root_noise; empty: none (zero).
  ModeTracker(DaeSystem& system, std::vector<double> unknown_floor = {});
  void set_unknown_floor(std::vector<double> unknown_floor);

  const DaeSystem& system() const { return system_; }
  int root_count() const { return system_.root_count(); }

  // ---- the run's element modes and histories (what the system's evaluations read) ----
  const ElementStates& modes() const { return system_.modes_; }
  /// Written directly: an element test setting a mode by hand (the run writes through the
  /// members below and the commits).
  ElementStates& modes() { return system_.modes_; }
  /// Puts every element back in the mode it starts a run in.
  void reset_modes() { system_.modes_.reset(); }
  /// Every element's mode and history now, to go back to with restore().
  ElementStates::Snapshot snapshot() const { return system_.modes_.snapshot(); }
  void restore(const ElementStates::Snapshot& snapshot) { system_.modes_.restore(snapshot); }
  /// Root functions at the start of the current step (previous) and at its end (now).
  std::vector<double>& previous() { return previous_; }
  std::vector<double>& now() { return now_; }
  bool on_boundary(int k) const { return on_boundary_[static_cast<std::size_t>(k)] != 0; }

  /// After a (re)start at (t, y): the roots there start the next step; a root at or below zero
  /// that the restart did not commit (zero, and not falling within its look-ahead) starts on
  /// its boundary, carried as +0, so that its first fall below zero is a crossing.
  void arm(double t, const double* y);
  /// The round-off level of root `local` of element e at state y: how much the root moves when
  /// each unknown it reads moves by its own rounding (|y_i| eps, at least the floor's), summed
  /// over them, times a safety factor. A root below zero by no more than this rests on its
  /// mode's boundary and does not leave the mode.
  double root_noise(int e, int local, double t, const double* y);
  /// After a step ending at (t_n, y) with now() holding the roots there: the roots that fell
  /// through zero since previous(), in root order, each at t_n (generation 0). A root below zero
  /// by no more than round-off is marked on its boundary and carried as +0 instead.
  void scan(double t_n, const double* y, std::vector<Crossing>& crossings);

  // ---- the mode changes of the current step ----
  /// A new step: no element has changed mode in it yet.
  void begin_step() { changed_.clear(), change_count_.clear(), change_time_.clear(); }
  /// Commits element e's root `local` falling through zero (direction -1; +1: rising through
  /// it) at (t, y), appending the event. True when the element changed mode (then
  /// record_change(e, t) has been called).
  bool commit(int e, int local, double t, const double* y, std::vector<EventRecord>& events, int direction = -1);
  /// Element e changed mode at t: its roots are ordinary again (a new mode), and the change
  /// counts for this step.
  void record_change(int e, double t);
  /// Commits the mode changes of the roots that fired (direction[k] = +1 / -1 for root k, 0 for
  /// roots that did not fire) at (t, y); appends what happened to `events`. Returns true when
  /// any mode changed (the static settle and the restarts; the step's bookkeeping above is left
  /// alone). With `changed_elements` (one flag per element): flagged elements are left alone
  /// and the ones that change are flagged, so that no element changes mode twice at one instant.
  bool commit_roots(double t, const double* y, const int* direction, std::vector<EventRecord>& events,
                    std::vector<char>* changed_elements = nullptr);
  /// At a (re)start at (t, y, y'): commits the roots that sit on their mode's boundary and are
  /// about to leave it (DaeSystem::boundary_roots_leaving); changed_elements as in commit_roots
  /// (repeated passes at one restart).
  bool commit_boundary(double t, const double* y, const double* yp, std::vector<EventRecord>& events,
                       std::vector<char>* changed_elements = nullptr);
  /// The run's t_end in its settings [time] (default 1): commit_boundary's look-ahead is
  /// 1e-6 min(1, t_end) (DaeSystem::boundary_roots_leaving). Each integrator sets it from its settings.
  void set_run_end(double t_end) { run_end_ = t_end; }
  /// How often element e changed mode in this step.
  int changes_of(int e) const;
  /// One flag per element: 1 for the elements whose last change in this step was at t.
  std::vector<char> changed_at(double t) const;
  /// The elements that changed mode in this step, in order of their first change.
  const std::vector<int>& changed_elements() const { return changed_; }
  /// At the end of a step without restart: the changed elements' roots at (t_n, y) in their
  /// new modes into now(), those resting on their boundary carried as +0.
  void refresh_changed(double t_n, const double* y);
  /// Marks root k as resting on its boundary (carried as +0 into the next step).
  void set_on_boundary(int k) { on_boundary_[static_cast<std::size_t>(k)] = 1; }
  /// The step is done: now() becomes the next step's previous().
  void end_step() { std::swap(previous_, now_); }

 private:
  /// Element e's root `local` crossing in `direction` at (t, y): its commit; appends the event.
  bool commit_element(int e, int local, int direction, double t, const double* y, std::vector<EventRecord>& events);

  DaeSystem& system_;
  double run_end_ = 1.0;  // [time] set_run_end
  std::vector<double> unknown_floor_;
  std::vector<double> previous_, now_;
  std::vector<char> on_boundary_;
  std::vector<double> y_probe_, g_element_, g_probe_;  // root_noise's scratch
  std::vector<int> changed_;         // elements that changed mode in this step
  std::vector<int> change_count_;    // how often each of them changed
  std::vector<double> change_time_;  // when each of them last changed
};

/// The crossings of the current step and their location on a StepInterpolant (see the file's comment).
class EventLocator {
 public:
  explicit EventLocator(const DaeSystem& system);

  /// The crossings of the current step, in time order once located.
  std::vector<Crossing>& queue() { return queue_; }
  /// Root `local` of element e at time t on the interpolant (only the element's unknowns interpolated).
  double root_at(StepInterpolant& step, int e, int local, double t);
  /// Illinois on [a, b] with g(a) > 0 >= g(b): the earliest time where root `local` of element
  /// e reaches zero, to `tolerance` [time].
  double locate(StepInterpolant& step, int e, int local, double a, double ga, double b, double gb, double tolerance);
  /// Locates every queued crossing in [step.t0(), step.t1()] (previous: the roots at t0, now: at
  /// t1) and sorts the queue by time (stable: simultaneous ones in root order).
  void locate_queue(StepInterpolant& step, const std::vector<double>& previous, const std::vector<double>& now,
                    double tolerance);
  /// The state at crossing c's located time from the interpolant's whole state; where round-off
  /// leaves the root a hair above zero there, the time moves forward by growing multiples of
  /// the tolerance (1, 4, 16, ...) until the root is at or below zero (at t1 it is). Each try is
  /// judged first on the element's own unknowns (corrected by their round-off difference from
  /// the whole state at the located time), the whole state interpolated only where that
  /// estimate is no longer above zero, and always at t1. Sets c.t; returns the state there.
  const double* event_state(StepInterpolant& step, Crossing& c, double tolerance);
  /// Queues a crossing found after the one at `index`, in time order.
  void insert_after(std::size_t index, const Crossing& c);

  // ---- a step known at its end alone (not dense): crossings are committed there ----
  /// direction[k] = -1 for a root that fell from >= 0 to < 0 between before and after, +1 for
  /// one that rose from < 0 to >= 0, else 0. True when any did.
  static bool step_end_crossings(const std::vector<double>& before, const std::vector<double>& after,
                                 std::vector<int>& direction);
  /// The same rule into the queue: every root that fired between before (the roots at the
  /// step's start) and after (at its end, t1), as a crossing at t1 with its direction, in root
  /// order. True when any did.
  bool queue_step_end_crossings(double t1, const std::vector<double>& before, const std::vector<double>& after);

 private:
  const DaeSystem& system_;
  std::vector<Crossing> queue_;
  std::vector<double> y_local_;    // one element's unknowns, interpolated
  std::vector<double> g_element_;  // one element's roots
};

}  // namespace railcrash
