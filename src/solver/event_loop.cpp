#include "railcrash/solver/event_loop.hpp"

#include <limits>

namespace railcrash {

namespace {

/// After a change at crossing c (queue position `index`) that the integrator goes on across:
/// the element's new mode may end within this step too. Its roots that are at or below zero at
/// t1 are located in [t_event, t1] (or committed at once when already outside at t_event) and
/// queued in time order.
void queue_new_mode_crossings(StepInterpolant& step, const double* y_end, ModeTracker& modes, EventLocator& locator,
                              const Crossing& c, std::size_t index, const double* y_at_event, double tolerance) {
  const DaeSystem& system = modes.system();
  const double t_n = step.t1();
  std::vector<double>& g_now = modes.now();
  const int offset = system.root_offset(c.element);
  const int count = system.element_root_count(c.element);
  const int generation = modes.changes_of(c.element);
  system.element_roots(c.element, t_n, y_end, g_now.data() + offset);
  for (int j = 0; j < count; ++j) {
    const double g_end = g_now[static_cast<std::size_t>(offset + j)];
    if (g_end > 0.0) continue;
    double g_start = locator.root_at(step, c.element, j, c.t);
    if (g_start <= 0.0 && g_start >= -modes.root_noise(c.element, j, c.t, y_at_event)) {
      // On the new mode's boundary by construction (see ModeTracker::root_noise): not a second
      // change at this instant. Still at the boundary at t1 (within round-off): the root starts
      // the next step armed at +0, so a real later crossing is found; clearly out by t1: the
      // crossing is located after the event.
      const double noise_end = modes.root_noise(c.element, j, t_n, y_end);
      if (g_end >= -noise_end) {
        modes.set_on_boundary(offset + j);
        continue;
      }
      g_start = std::numeric_limits<double>::min();
    }
    const double t_next = g_start > 0.0 ? locator.locate(step, c.element, j, c.t, g_start, t_n, g_end, tolerance) : c.t;
    locator.insert_after(index, Crossing{t_next, c.element, j, generation});
  }
}

/// A step known at its end alone (not dense): every queued crossing at t1, all at once, in root
/// order; an element changes mode once (its other roots belonged to the mode it left). The
/// handler sees the old modes once (before_change, the first crossing) and, when any mode
/// changed, restarts once at t1 (restart_at: the step's end in the new modes).
bool commit_at_step_end(const double* y_end, ModeTracker& modes, EventLocator& locator, EventHandler& handler,
                        std::vector<EventRecord>& events) {
  const std::vector<Crossing>& crossings = locator.queue();
  modes.begin_step();
  const Crossing first = crossings.front();
  handler.before_change(first, y_end);
  events.clear();
  bool changed = false;
  for (const Crossing& c : crossings) {
    if (modes.changes_of(c.element) > 0) continue;
    if (!modes.commit(c.element, c.local, c.t, y_end, events, c.direction)) continue;
    changed = true;
    handler.committed(c);
  }
  if (changed) handler.restart_at(first, y_end);
  modes.end_step();
  return changed;
}

}  // namespace

bool commit_crossings(StepInterpolant& step, const double* y_end, ModeTracker& modes, EventLocator& locator,
                      EventHandler& handler, double tolerance, std::vector<EventRecord>& events) {
  if (!step.dense()) return commit_at_step_end(y_end, modes, locator, handler, events);
  std::vector<Crossing>& crossings = locator.queue();
  modes.begin_step();
  bool restart_now = false;
  for (std::size_t i = 0; i < crossings.size(); ++i) {
    Crossing c = crossings[i];
    if (modes.changes_of(c.element) != c.generation) continue;  // found in a mode the element has left
    if (c.generation >= 20) restart_now = true;  // an element switching back and forth within one step: restart
    // The state at the event from the interpolant's whole state (the same numbers a restart
    // uses), nudged to where the root is at or below zero (EventLocator::event_state).
    const double* y_at_event = locator.event_state(step, c, tolerance);
    handler.before_change(c, y_at_event);
    events.clear();
    if (restart_now)
      modes.record_change(c.element, c.t);
    else if (!modes.commit(c.element, c.local, c.t, y_at_event, events))
      continue;
    handler.committed(c);
    if (!restart_now && handler.goes_on_across(c, y_at_event, events)) {
      queue_new_mode_crossings(step, y_end, modes, locator, c, i, y_at_event, tolerance);
      continue;
    }
    handler.restart_at(c, y_at_event);
    return true;
  }
  modes.refresh_changed(step.t1(), y_end);  // the changed elements' roots at t1, in their new modes
  modes.end_step();
  return false;
}

}  // namespace railcrash
