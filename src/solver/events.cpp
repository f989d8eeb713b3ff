#include "railcrash/solver/events.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace railcrash {

// ---- ModeTracker ----

ModeTracker::ModeTracker(DaeSystem& system, std::vector<double> unknown_floor) : system_(system) {
  const auto roots = static_cast<std::size_t>(system_.root_count());
  previous_.assign(roots, 0.0);
  now_.assign(roots, 0.0);
  on_boundary_.assign(roots, 0);
  y_probe_.assign(static_cast<std::size_t>(system_.size()), 0.0);
  set_unknown_floor(std::move(unknown_floor));
}

void ModeTracker::set_unknown_floor(std::vector<double> unknown_floor) {
  unknown_floor_ = std::move(unknown_floor);
  unknown_floor_.resize(static_cast<std::size_t>(system_.size()), 0.0);
}

void ModeTracker::arm(double t, const double* y) {
  if (system_.root_count() > 0) system_.roots(t, y, previous_.data());
  for (std::size_t k = 0; k < previous_.size(); ++k) {
    on_boundary_[k] = 0;
    if (previous_[k] <= 0.0) {
      previous_[k] = std::numeric_limits<double>::min();
      on_boundary_[k] = 1;
    }
  }
}

double ModeTracker::root_noise(int e, int local, double t, const double* y) {
  constexpr double kSafety = 64.0;
  const double eps = std::numeric_limits<double>::epsilon();
  const std::vector<int>& unknowns = system_.element_unknowns(e);
  // Only the element's own unknowns are read (y_probe_ has the model's size, the rest unused):
  // clearing the whole vector per call cost O(N) per crossing in a train.
  for (const int i : unknowns) y_probe_[static_cast<std::size_t>(i)] = y[i];
  const int count = system_.element_root_count(e);
  g_element_.resize(static_cast<std::size_t>(count));
  g_probe_.resize(static_cast<std::size_t>(count));
  system_.element_roots(e, t, y_probe_.data(), g_element_.data());
  const double g0 = g_element_[static_cast<std::size_t>(local)];
  double noise = kSafety * eps * std::abs(g0);
  for (const int i : unknowns) {
    double& yi = y_probe_[static_cast<std::size_t>(i)];
    const double saved = yi;
    const double magnitude = std::max(std::abs(saved), unknown_floor_[static_cast<std::size_t>(i)]);
    const double delta = 1e-7 * magnitude;
    yi = saved + delta;
    system_.element_roots(e, t, y_probe_.data(), g_probe_.data());
    yi = saved;
    noise += kSafety * eps * magnitude * std::abs(g_probe_[static_cast<std::size_t>(local)] - g0) / delta;
  }
  return noise;
}

void ModeTracker::scan(double t_n, const double* y, std::vector<Crossing>& crossings) {
  crossings.clear();
  const int root_count = system_.root_count();
  for (int k = 0; k < root_count; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    if (now_[kk] > 0.0) {
      on_boundary_[kk] = 0;  // inside its mode: an ordinary root again
      continue;
    }
    if (!(previous_[kk] > 0.0)) continue;
    const int owner = system_.root_owner(k);
    const int local = k - system_.root_offset(owner);
    if (now_[kk] >= -root_noise(owner, local, t_n, y)) {
      // Below zero by no more than round-off: an element resting on a boundary (a leveler at a
      // kink), not leaving its mode; carried as +0 until clearly below.
      on_boundary_[kk] = 1;
      now_[kk] = std::numeric_limits<double>::min();
      continue;
    }
    crossings.push_back({t_n, owner, local, 0});
  }
}

bool ModeTracker::commit_element(int e, int local, int direction, double t, const double* y,
                                 std::vector<EventRecord>& events) {
  const Element& el = *system_.model().elements()[static_cast<std::size_t>(e)];
  Element::Event event;
  if (!el.commit(local, direction, t, system_.element_state(e, y), system_.element_multipliers(e, y),
                 system_.modes_.of(static_cast<std::size_t>(e)), event))
    return false;
  events.push_back({t, el.name(), event.what, event.value, event.kind == Element::EventKind::Kink});
  return true;
}

bool ModeTracker::commit_roots(double t, const double* y, const int* direction, std::vector<EventRecord>& events,
                               std::vector<char>* changed_elements) {
  bool changed = false;
  for (int e = 0; e < system_.element_count(); ++e) {
    if (changed_elements && (*changed_elements)[static_cast<std::size_t>(e)]) continue;
    const int offset = system_.root_offset(e);
    for (int k = 0; k < system_.element_root_count(e); ++k) {
      const int d = direction[offset + k];
      if (d == 0 || !commit_element(e, k, d, t, y, events)) continue;
      changed = true;
      if (changed_elements) (*changed_elements)[static_cast<std::size_t>(e)] = 1;
      break;  // the element's other roots belonged to the mode it just left
    }
  }
  return changed;
}

bool ModeTracker::commit_boundary(double t, const double* y, const double* yp, std::vector<EventRecord>& events,
                                  std::vector<char>* changed_elements) {
  std::vector<int> direction;
  return system_.boundary_roots_leaving(t, y, yp, run_end_, direction) &&
         commit_roots(t, y, direction.data(), events, changed_elements);
}

bool ModeTracker::commit(int e, int local, double t, const double* y, std::vector<EventRecord>& events, int direction) {
  if (!commit_element(e, local, direction, t, y, events)) return false;
  record_change(e, t);
  return true;
}

void ModeTracker::record_change(int e, double t) {
  const int offset = system_.root_offset(e);
  const int count = system_.element_root_count(e);
  for (int j = 0; j < count; ++j) on_boundary_[static_cast<std::size_t>(offset + j)] = 0;  // a new mode
  const auto seen = std::find(changed_.begin(), changed_.end(), e);
  if (seen == changed_.end()) {
    changed_.push_back(e);
    change_count_.push_back(1);
    change_time_.push_back(t);
  } else {
    const auto index = static_cast<std::size_t>(seen - changed_.begin());
    ++change_count_[index];
    change_time_[index] = t;
  }
}

int ModeTracker::changes_of(int e) const {
  const auto it = std::find(changed_.begin(), changed_.end(), e);
  return it == changed_.end() ? 0 : change_count_[static_cast<std::size_t>(it - changed_.begin())];
}

std::vector<char> ModeTracker::changed_at(double t) const {
  std::vector<char> flags(static_cast<std::size_t>(system_.element_count()), 0);
  for (std::size_t k = 0; k < changed_.size(); ++k)
    if (change_time_[k] == t) flags[static_cast<std::size_t>(changed_[k])] = 1;
  return flags;
}

void ModeTracker::refresh_changed(double t_n, const double* y) {
  for (const int e : changed_) system_.element_roots(e, t_n, y, now_.data() + system_.root_offset(e));
  for (const int e : changed_) {
    const int offset = system_.root_offset(e);
    const int count = system_.element_root_count(e);
    for (int k = offset; k < offset + count; ++k)
      if (on_boundary_[static_cast<std::size_t>(k)] && now_[static_cast<std::size_t>(k)] <= 0.0)
        now_[static_cast<std::size_t>(k)] = std::numeric_limits<double>::min();
  }
}

// ---- EventLocator ----

EventLocator::EventLocator(const DaeSystem& system) : system_(system) {
  y_local_.assign(static_cast<std::size_t>(system_.size()), 0.0);
}

double EventLocator::root_at(StepInterpolant& step, int e, int local, double t) {
  step.unknowns_at(system_.element_unknowns(e), t, y_local_.data());
  g_element_.resize(static_cast<std::size_t>(system_.element_root_count(e)));
  system_.element_roots(e, t, y_local_.data(), g_element_.data());
  return g_element_[static_cast<std::size_t>(local)];
}

double EventLocator::locate(StepInterpolant& step, int e, int local, double a, double ga, double b, double gb,
                            double tolerance) {
  int side = 0;
  for (int iteration = 0; iteration < 100 && b - a > tolerance; ++iteration) {
    double t = b - gb * (b - a) / (gb - ga);
    const double margin = 0.1 * tolerance;
    t = std::min(std::max(t, a + margin), b - margin);
    const double g = root_at(step, e, local, t);
    if (g > 0.0) {
      a = t, ga = g;
      if (side == -1) gb *= 0.5;
      side = -1;
    } else {
      b = t, gb = g;
      if (side == 1) ga *= 0.5;
      side = 1;
    }
  }
  return b;
}

void EventLocator::locate_queue(StepInterpolant& step, const std::vector<double>& previous,
                                const std::vector<double>& now, double tolerance) {
  for (Crossing& c : queue_) {
    const auto k = static_cast<std::size_t>(system_.root_offset(c.element) + c.local);
    c.t = locate(step, c.element, c.local, step.t0(), previous[k], step.t1(), now[k], tolerance);
  }
  std::stable_sort(queue_.begin(), queue_.end(), [](const Crossing& x, const Crossing& z) { return x.t < z.t; });
}

const double* EventLocator::event_state(StepInterpolant& step, Crossing& c, double tolerance) {
  const double t_n = step.t1();
  double t_event = c.t;
  const double* y_at_event = step.state_at(t_event);
  g_element_.resize(static_cast<std::size_t>(system_.element_root_count(c.element)));
  system_.element_roots(c.element, t_event, y_at_event, g_element_.data());
  double g_event = g_element_[static_cast<std::size_t>(c.local)];
  const double mismatch = g_event > 0.0 ? g_event - root_at(step, c.element, c.local, c.t) : 0.0;
  for (double nudge = tolerance; g_event > 0.0 && t_event < t_n; nudge *= 4.0) {
    t_event = std::min(t_n, c.t + nudge);
    if (t_event < t_n && root_at(step, c.element, c.local, t_event) + mismatch > 0.0) continue;
    y_at_event = step.state_at(t_event);
    system_.element_roots(c.element, t_event, y_at_event, g_element_.data());
    g_event = g_element_[static_cast<std::size_t>(c.local)];
  }
  c.t = t_event;
  return y_at_event;
}

void EventLocator::insert_after(std::size_t index, const Crossing& c) {
  queue_.insert(std::upper_bound(queue_.begin() + static_cast<std::ptrdiff_t>(index) + 1, queue_.end(), c,
                                 [](const Crossing& x, const Crossing& z) { return x.t < z.t; }),
                c);
}

namespace {

/// Euler's rule for a root between a step's start (g0) and end (g1): -1 for a fall from >= 0 to
/// < 0, +1 for a rise from < 0 to >= 0, else 0.
int step_end_direction(double g0, double g1) { return (g0 >= 0.0 && g1 < 0.0) ? -1 : (g0 < 0.0 && g1 >= 0.0) ? 1 : 0; }

}  // namespace

bool EventLocator::step_end_crossings(const std::vector<double>& before, const std::vector<double>& after,
                                      std::vector<int>& direction) {
  bool fired = false;
  for (std::size_t k = 0; k < after.size(); ++k) {
    direction[k] = step_end_direction(before[k], after[k]);
    fired = fired || direction[k] != 0;
  }
  return fired;
}

bool EventLocator::queue_step_end_crossings(double t1, const std::vector<double>& before, const std::vector<double>& after) {
  queue_.clear();
  for (std::size_t k = 0; k < after.size(); ++k) {
    const int direction = step_end_direction(before[k], after[k]);
    if (direction == 0) continue;
    const int owner = system_.root_owner(static_cast<int>(k));
    queue_.push_back({t1, owner, static_cast<int>(k) - system_.root_offset(owner), 0, direction});
  }
  return !queue_.empty();
}

}  // namespace railcrash
