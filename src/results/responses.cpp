#include "railcrash/results/responses.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "railcrash/elements/anticlimber.hpp"
#include "railcrash/results/results.hpp"

namespace railcrash {

ResponseTracker::ResponseTracker(const DaeSystem& system, const ResponseSettings& settings)
    : system_(system), settings_(settings) {
  responses_.max_crush.assign(settings.crush_gauges.size(), 0.0);
  if (settings.anticlimber.empty()) return;
  const auto& elements = system.model().elements();
  for (std::size_t e = 0; e < elements.size(); ++e)
    if (elements[e]->name() == settings.anticlimber) anticlimber_element_ = static_cast<int>(e);
  const Anticlimber* anticlimber =
      anticlimber_element_ < 0 ? nullptr : as_anticlimber(*elements[static_cast<std::size_t>(anticlimber_element_)]);
  if (!anticlimber)
    throw InputError(SourceLocation{system.model().file, 0}.prefix() + "responses: 'anticlimber: " + settings.anticlimber +
                     "' must name an element of type anticlimber");
  const auto& names = system.output_names();
  const auto column_of = [&](OutputRole role) {
    const auto it = std::find(names.begin(), names.end(), settings.anticlimber + "." + anticlimber->output_with_role(role));
    RAILCRASH_DEMAND(it != names.end());
    return static_cast<int>(it - names.begin());
  };
  vertical_force_column_ = column_of(OutputRole::VerticalInterlockForce);
  horizontal_deformation_column_ = column_of(OutputRole::Crush);
  responses_.vertical_yield_force = settings.vertical_yield_force.value_or(anticlimber->vertical_yield_force());
}

double ResponseTracker::gauge_length(const CrushGauge& gauge, const double* y) const {
  const auto position = [&](const PointRef& p) {
    if (p.body == kGround) return Vec2<double>{p.sx, p.sy};
    const Pose<double> q{y[3 * p.body], y[3 * p.body + 1], y[3 * p.body + 2]};
    return point_position(q, p.sx, p.sy);
  };
  const Vec2<double> d = position(gauge.front) - position(gauge.rear);
  return std::sqrt(dot(d, d));
}

void ResponseTracker::sample(double t, const double* y, const double*, const double*, const double* outputs) {
  if (!started_) {  // lengths at the start of the run (after any settling)
    for (const CrushGauge& g : settings_.crush_gauges) initial_length_.push_back(gauge_length(g, y));
    started_ = true;
  }
  track_extrema(y, outputs, FreshOutputs{});
  track_collision_post(t, y, outputs, FreshOutputs{});
}

void ResponseTracker::step(double t, const double* y, const double*, const double* outputs, const FreshOutputs& fresh) {
  if (!started_) return;  // (events at the start come before the first sample)
  track_extrema(y, outputs, fresh);
  track_collision_post(t, y, outputs, fresh);
}

void ResponseTracker::mark_step_columns(std::vector<char>& columns) const {
  for (const int column : {vertical_force_column_, horizontal_deformation_column_})
    if (column >= 0) columns[static_cast<std::size_t>(column)] = 1;
}

double ResponseTracker::relative_velocity(const double* y) const {
  const Element& e = *system_.model().elements()[static_cast<std::size_t>(anticlimber_element_)];
  const int nq = system_.body_unknowns();
  const auto vx = [&](int slot) { return e.slot_body(slot) == kGround ? 0.0 : y[nq + 3 * e.slot_body(slot)]; };
  return std::abs(vx(1) - vx(0));
}

void ResponseTracker::track_collision_post(double t, const double* y, const double* outputs, const FreshOutputs& fresh) {
  if (anticlimber_element_ < 0 || !fresh.has(horizontal_deformation_column_)) return;
  const TrackedState state{t, outputs[horizontal_deformation_column_], relative_velocity(y)};
  if (responses_.overridden) {
    // States after one already at the post cannot decide when it was first reached.
    if (settings_.override_velocity_at == ResponseSettings::OverrideVelocityAt::CollisionPost && t <= at_post_by_) {
      after_override_.push_back(state);
      if (state.crush >= settings_.collision_post_distance) at_post_by_ = t;
    }
  } else if (!have_last_ || t >= last_.t) {  // (samples inside a step arrive after its end)
    last_ = state;
    have_last_ = true;
  }
}

void ResponseTracker::track_extrema(const double* y, const double* outputs, const FreshOutputs& fresh) {
  for (std::size_t k = 0; k < settings_.crush_gauges.size(); ++k)
    responses_.max_crush[k] = std::max(responses_.max_crush[k], initial_length_[k] - gauge_length(settings_.crush_gauges[k], y));
  if (vertical_force_column_ < 0) return;
  if (!vertical_window_closed_ && fresh.has(vertical_force_column_))
    responses_.max_vertical_force = std::max(responses_.max_vertical_force, std::abs(outputs[vertical_force_column_]));
  if (fresh.has(horizontal_deformation_column_))
    responses_.max_anticlimber_crush = std::max(responses_.max_anticlimber_crush, outputs[horizontal_deformation_column_]);
}

void ResponseTracker::event(const EventRecord& record, const double* y) {
  if (record.element != settings_.anticlimber) return;
  // The window of R2's largest vertical force closes at the first event that ends it (the
  // sample at the event time, written before the mode change, is still inside).
  using Window = ResponseSettings::VerticalForceWindow;
  if ((settings_.vertical_force_window == Window::UntilLargestCrush &&
       record.what.find("horizontal unloading") != std::string::npos) ||
      (settings_.vertical_force_window == Window::UntilSeparation && record.what.find("separation") != std::string::npos))
    vertical_window_closed_ = true;
  if (responses_.overridden) return;
  if (record.what.find("override") == std::string::npos) return;
  responses_.overridden = true;
  responses_.override_time = record.t;
  responses_.relative_velocity_at_override = relative_velocity(y);
  responses_.override_relative_velocity = responses_.relative_velocity_at_override;
  // The report's relative velocity is taken when the end sill reaches the collision post
  // (result(), from the states tracked from here on and the last one before).
  if (have_last_) {
    after_override_.push_back(last_);
    if (last_.crush >= settings_.collision_post_distance) at_post_by_ = last_.t;
  }
}

void ResponseTracker::find_collision_post(Responses& r) const {
  std::vector<TrackedState> states = after_override_;
  std::stable_sort(states.begin(), states.end(), [](const TrackedState& a, const TrackedState& b) { return a.t < b.t; });
  const double post = settings_.collision_post_distance;
  r.override_relative_velocity = 0.0;  // never reached: the end sill never hits the post
  if (states.empty() || states.front().crush >= post) {  // already past it when the faces passed each other
    r.collision_post_reached = !states.empty();
    r.collision_post_time = r.override_time;
    r.override_relative_velocity = r.collision_post_reached ? r.relative_velocity_at_override : 0.0;
    return;
  }
  for (std::size_t i = 1; i < states.size(); ++i) {
    if (states[i].crush < post) continue;
    const TrackedState& a = states[i - 1];
    const TrackedState& b = states[i];
    const double s = (post - a.crush) / (b.crush - a.crush);  // b.crush > a.crush here
    r.collision_post_reached = true;
    r.collision_post_time = std::max(r.override_time, a.t + s * (b.t - a.t));
    r.override_relative_velocity = a.velocity + s * (b.velocity - a.velocity);
    return;
  }
}

Responses ResponseTracker::result() const {
  Responses r = responses_;
  double crush = 0.0;
  for (double c : r.max_crush) crush = settings_.total_crush ? crush + c : std::max(crush, c);
  if (settings_.crush_from_anticlimber) crush = r.max_anticlimber_crush;
  r.r1 = settings_.reference_crush > 0.0 ? crush / settings_.reference_crush : 0.0;
  if (r.overridden && settings_.override_velocity_at == ResponseSettings::OverrideVelocityAt::CollisionPost)
    find_collision_post(r);
  if (r.overridden)
    r.r2 = 1.0 + (settings_.reference_velocity > 0.0 ? r.override_relative_velocity / settings_.reference_velocity : 0.0);
  else
    r.r2 = r.vertical_yield_force > 0.0 ? r.max_vertical_force / r.vertical_yield_force : 0.0;
  r.r3 = (r.r1 < 1.0 && r.r2 < 1.0) ? std::max(r.r1, r.r2) : r.r1 + r.r2;
  return r;
}

std::string ResponseTracker::json() const {
  const Responses r = result();
  std::ostringstream j;
  j << "{\"R1\": " << json_number(r.r1) << ", \"R2\": " << json_number(r.r2) << ", \"R3\": " << json_number(r.r3)
    << ", \"override\": " << (r.overridden ? "true" : "false")
    << ", \"override_time\": " << (r.overridden ? json_number(r.override_time) : "null")
    << ", \"override_relative_velocity\": " << json_number(r.override_relative_velocity)
    << ", \"override_velocity_at\": "
    << json_string(settings_.override_velocity_at == ResponseSettings::OverrideVelocityAt::CollisionPost ? "collision_post" : "override")
    << ", \"relative_velocity_at_override\": " << json_number(r.relative_velocity_at_override)
    << ", \"collision_post_distance\": " << json_number(settings_.collision_post_distance)
    << ", \"collision_post_reached\": " << (r.collision_post_reached ? "true" : "false")
    << ", \"collision_post_time\": " << (r.collision_post_reached ? json_number(r.collision_post_time) : "null")
    << ", \"max_vertical_anticlimber_force\": " << json_number(r.max_vertical_force)
    << ", \"max_anticlimber_crush\": " << json_number(r.max_anticlimber_crush)
    << ", \"vertical_yield_force\": " << json_number(r.vertical_yield_force) << ", \"vertical_force_window\": "
    << json_string(settings_.vertical_force_window == ResponseSettings::VerticalForceWindow::WholeRun ? "whole_run"
                   : settings_.vertical_force_window == ResponseSettings::VerticalForceWindow::UntilLargestCrush
                       ? "until_largest_crush"
                       : "until_separation")
    << ", \"max_crush\": {";
  for (std::size_t k = 0; k < settings_.crush_gauges.size(); ++k)
    j << (k ? ", " : "") << json_string(settings_.crush_gauges[k].name) << ": " << json_number(r.max_crush[k]);
  j << "}, \"crush_measure\": "
    << json_string(settings_.crush_from_anticlimber ? "anticlimber" : settings_.total_crush ? "total" : "largest")
    << ", \"reference_crush\": " << json_number(settings_.reference_crush)
    << ", \"reference_velocity\": " << json_number(settings_.reference_velocity) << "}";
  return j.str();
}

}  // namespace railcrash
