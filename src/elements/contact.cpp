#include "railcrash/elements/contact.hpp"

#include <cmath>
#include <limits>

namespace railcrash {

SurfaceContact::SurfaceContact(ElementSpec& spec, bool wheel_rail)
    : ForceElement(spec.name, spec.type, spec.points, spec.where), wheel_rail_(wheel_rail) {
  spec.require_points(1);
  ParameterReader& p = *spec.parameters;
  stiffness = p.required_positive("stiffness");
  damping = p.optional_nonnegative("damping").value_or(0.0);
  friction = p.optional_nonnegative("friction").value_or(0.0);
  friction_velocity = p.optional_positive("friction_velocity").value_or(0.01);
  if (wheel_rail) {
    // Report type 18: the wheel centre against the rail head line.
    const double wheel_radius = p.required_positive("wheel_radius");
    const double rail_height = p.number("rail_height").value_or(0.0);
    stiffness_above = p.optional_positive("stiffness_above").value_or(stiffness);
    breakpoint = p.optional_positive("breakpoint").value_or(std::numeric_limits<double>::infinity());
    surface = Surface::Line;
    px = 0.0;
    py = rail_height + wheel_radius;
    nx = 0.0;
    ny = 1.0;
    return;
  }
  stiffness_above = stiffness;
  breakpoint = std::numeric_limits<double>::infinity();
  const auto line_point = p.vector("line_point", 2);
  const auto line_normal = p.vector("line_normal", 2);
  const auto center = p.vector("circle_center", 2);
  const auto circle_radius = p.optional_positive("circle_radius");
  inside = p.flag("inside").value_or(false);
  if (line_point && !center) {
    if (!line_normal) p.fail("line_normal", "a line surface needs 'line_normal' [nx, ny] (pointing to the free side)");
    const double norm = std::hypot((*line_normal)[0], (*line_normal)[1]);
    if (!(norm > 0.0)) p.fail("line_normal", "'line_normal' must be a non-zero direction");
    surface = Surface::Line;
    px = (*line_point)[0];
    py = (*line_point)[1];
    nx = (*line_normal)[0] / norm;
    ny = (*line_normal)[1] / norm;
  } else if (center && !line_point) {
    if (!circle_radius) p.fail("circle_radius", "a circle surface needs 'circle_radius'");
    surface = Surface::Circle;
    px = (*center)[0];
    py = (*center)[1];
    radius = *circle_radius;
  } else {
    p.fail("line_point", "give the surface either as a line (line_point, line_normal) or as a circle "
                         "(circle_center, circle_radius, optional inside: true), not both");
  }
}

void SurfaceContact::enter_mode(double penetration, double rate) {
  if (penetration < 0.0 || (penetration == 0.0 && rate <= 0.0)) {
    state_.mode = Mode::Open;
    return;
  }
  state_.segment = penetration > breakpoint ? 1 : 0;
  state_.mode = normal_force(penetration, rate, state_.segment) >= 0.0 ? Mode::Contact : Mode::Released;
}

void SurfaceContact::initialize(const ElementState<double>& initial) {
  const Kinematics<double> k = kinematics(initial);
  state_ = State{};
  enter_mode(k.penetration, k.rate);
  initial_state_ = state_;
}

void SurfaceContact::roots(double, const ElementState<double>& s, const double*, double* g) const {
  const Kinematics<double> k = kinematics(s);
  g[0] = g[1] = g[2] = 1.0;
  switch (state_.mode) {
    case Mode::Open:
      g[0] = -k.penetration;  // falls through 0 when the point reaches the surface
      break;
    case Mode::Contact:
      g[0] = k.penetration;
      g[1] = normal_force(k.penetration, k.rate, state_.segment);
      if (std::isfinite(breakpoint)) g[2] = state_.segment == 0 ? breakpoint - k.penetration : k.penetration - breakpoint;
      break;
    case Mode::Released:
      g[0] = k.penetration;
      g[1] = -normal_force(k.penetration, k.rate, k.penetration > breakpoint ? 1 : 0);
      break;
  }
}

bool SurfaceContact::commit(int index, int direction, double, const ElementState<double>& s, const double*, Event& event) {
  if (direction > 0) return false;  // every root above is written to fall through 0
  const Kinematics<double> k = kinematics(s);
  switch (state_.mode) {
    case Mode::Open:
      if (index != 0) return false;
      state_.mode = Mode::Contact;
      state_.segment = 0;
      event = {wheel_rail_ ? "wheel contact" : "contact", k.rate};
      return true;
    case Mode::Contact:
      if (index == 0) {
        state_.mode = Mode::Open;
        event = {wheel_rail_ ? "wheel lift-off" : "separation", k.rate};
      } else if (index == 1) {
        state_.mode = Mode::Released;
        event = {wheel_rail_ ? "wheel unloaded (damper would pull)" : "released (damper would pull)", k.penetration};
      } else {
        state_.segment = 1 - state_.segment;
        event = {state_.segment == 1 ? "above breakpoint" : "below breakpoint", k.penetration};
      }
      return true;
    case Mode::Released:
      if (index == 0) {
        state_.mode = Mode::Open;
        event = {wheel_rail_ ? "wheel lift-off" : "separation", k.rate};
      } else {
        state_.mode = Mode::Contact;
        state_.segment = k.penetration > breakpoint ? 1 : 0;
        event = {wheel_rail_ ? "wheel contact" : "contact", k.penetration};
      }
      return true;
  }
  return false;
}

void SurfaceContact::stiffest_force_jacobian(double t, const ElementState<double>& s, ForceBlock& df_dq, ForceBlock& df_dv) {
  const State saved = state_;
  state_ = {Mode::Contact, stiffness_above > stiffness ? 1 : 0};
  std::array<Pose<double>, 2> f{};
  add_force_jacobian(t, s, f, df_dq, df_dv);
  state_ = saved;
}

double SurfaceContact::potential_energy(const ElementState<double>& s) const {
  if (state_.mode != Mode::Contact) return 0.0;
  const double d = kinematics(s).penetration;
  if (state_.segment == 0) return 0.5 * stiffness * d * d;
  const double above = d - breakpoint;
  return 0.5 * stiffness * breakpoint * breakpoint + stiffness * breakpoint * above + 0.5 * stiffness_above * above * above;
}

void SurfaceContact::outputs(const ElementState<double>& s, const double*, double* out) const {
  const Kinematics<double> k = kinematics(s);
  const double normal = state_.mode == Mode::Contact ? normal_force(k.penetration, k.rate, state_.segment) : 0.0;
  out[0] = normal;
  out[1] = friction > 0.0 ? -friction * normal * std::tanh(k.slip / friction_velocity) : 0.0;
  out[2] = k.penetration;
}

void register_contact_elements(ElementRegistry& registry) {
  registry.add("contact", [](ElementSpec& s) { return std::make_unique<SurfaceContact>(s, false); });
  registry.add("wheel_rail", [](ElementSpec& s) { return std::make_unique<SurfaceContact>(s, true); });
}

}  // namespace railcrash
