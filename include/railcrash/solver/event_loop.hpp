// The loop over a step's crossings (issue 37 item 5), written once for every integrator. Its
// policy follows the step (StepInterpolant::dense):
// * dense (IDA): each crossing of the EventLocator's queue, in time order, is moved to a state
//   at or below zero (EventLocator::event_state), committed through the ModeTracker, and then
//   either gone on across (the integrator keeps its step's end; the element's new mode may end
//   within the step too: those crossings are located and queued) or restarted at;
// * known at its end alone (Euler): every crossing (EventLocator::queue_step_end_crossings) is
//   committed at the step's end, all at once, and the integrator restarts there once.
// What depends on the integrator (its samples before the change, whether it can go on across
// one, its restart) is an EventHandler's.
#pragma once

#include <vector>

#include "railcrash/solver/events.hpp"

namespace railcrash {

/// What a dense integrator decides about each mode change located inside its step.
class EventHandler {
 public:
  virtual ~EventHandler() = default;
  /// Before crossing c's mode change at c.t (y_at_event: the state there, in the old modes):
  /// the samples up to it, the observers' look at the old modes, and what the handler keeps of
  /// them for goes_on_across.
  virtual void before_change(const Crossing& c, const double* y_at_event) = 0;
  /// A mode change inside the step was committed (or forced, see commit_crossings).
  virtual void committed(const Crossing& /*c*/) {}
  /// After crossing c's change was committed (events: what changed): true when the integrator
  /// goes on across it with its step's end (it has reported the events then); false: restart.
  virtual bool goes_on_across(const Crossing& c, const double* y_at_event, const std::vector<EventRecord>& events) = 0;
  /// Restarts the integrator at crossing c's event (it reports the events; the step's end is
  /// discarded).
  virtual void restart_at(const Crossing& c, const double* y_at_event) = 0;
};

/// Commits the crossings in the locator's queue (located and sorted: locate_queue) in time
/// order on `step`; y_end: the integrator's state at step.t1(), whose roots are in
/// modes.now(); tolerance: the location's [time]; events: scratch for each change's records.
/// A crossing found in a mode its element has since left is skipped; an element that changed
/// 20 times within the step forces a restart. Returns true when the integrator restarted
/// (the step ends there); otherwise the changed elements' roots at t1 are refreshed and the
/// step is done (ModeTracker::end_step).
/// On a step known at its end alone (not dense; the queue from queue_step_end_crossings, the
/// tolerance unused): the handler's before_change once (the first crossing), every crossing
/// committed at t1 with its direction (an element once), committed() for each that changed a
/// mode and then restart_at once, and the step is done (ModeTracker::end_step; the handler's
/// restart has put the new modes' roots at t1 into modes.now()). Returns true when a mode changed.
bool commit_crossings(StepInterpolant& step, const double* y_end, ModeTracker& modes, EventLocator& locator,
                      EventHandler& handler, double tolerance, std::vector<EventRecord>& events);

}  // namespace railcrash
