#include "railcrash/elements/contact.hpp"

#include <cmath>
#include <limits>

namespace railcrash {

SurfaceContact::SurfaceContact(ElementSpec& spec, bool wheel_rail)
    : HybridElement(spec.name, spec.type, spec.points, spec.where), wheel_rail_(wheel_rail) {
  ParameterReader& p = *spec.parameters;
  stiffness = p.value("stiffness");
  damping = p.value("damping");
  friction = p.value("friction");
  friction_velocity = p.value("friction_velocity");
  if (wheel_rail) {
    // Report type 18: the wheel centre against the rail head line.
    const double wheel_radius = p.value("wheel_radius");
    const double rail_height = p.value("rail_height");
    stiffness_above = p.number("stiffness_above").value_or(stiffness);
    breakpoint = p.number("breakpoint").value_or(std::numeric_limits<double>::infinity());
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
  const auto circle_radius = p.number("circle_radius");
  inside = *p.flag("inside");
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

std::optional<Element::GroundSurface> SurfaceContact::ground_surface() const {
  if (type() == std::string("wheel_rail")) return std::nullopt;
  GroundSurface g;
  g.kind = surface == Surface::Line ? GroundSurface::Kind::Line : GroundSurface::Kind::Circle;
  g.x = px;
  g.y = py;
  g.nx = nx;
  g.ny = ny;
  g.radius = radius;
  g.inside = inside;
  return g;
}

void SurfaceContact::enter_mode(State& st, double penetration, double rate) const {
  if (penetration < 0.0 || (penetration == 0.0 && rate <= 0.0)) {
    st.mode = Mode::Open;
    return;
  }
  st.segment = penetration > breakpoint ? 1 : 0;
  st.mode = normal_force(penetration, rate, st.segment) >= 0.0 ? Mode::Contact : Mode::Released;
}

void SurfaceContact::initialize(const ElementState<double>& initial) {
  const Kinematics<double> k = kinematics(initial);
  initial_state_ = State{};
  enter_mode(initial_state_, k.penetration, k.rate);
}

void SurfaceContact::roots_in(const State& st, const ElementState<double>& s, double* g) const {
  const Kinematics<double> k = kinematics(s);
  g[0] = g[1] = g[2] = 1.0;
  switch (st.mode) {
    case Mode::Open:
      g[0] = -k.penetration;  // falls through 0 when the point reaches the surface
      break;
    case Mode::Contact:
      g[0] = k.penetration;
      g[1] = normal_force(k.penetration, k.rate, st.segment);
      if (std::isfinite(breakpoint)) g[2] = st.segment == 0 ? breakpoint - k.penetration : k.penetration - breakpoint;
      break;
    case Mode::Released:
      g[0] = k.penetration;
      g[1] = -normal_force(k.penetration, k.rate, k.penetration > breakpoint ? 1 : 0);
      break;
  }
}

bool SurfaceContact::commit_in(State& st, int index, int direction, double, const ElementState<double>& s,
                               Event& event) const {
  if (direction > 0) return false;  // every root above is written to fall through 0
  const Kinematics<double> k = kinematics(s);
  switch (st.mode) {
    case Mode::Open:
      if (index != 0) return false;
      st.mode = Mode::Contact;
      st.segment = 0;
      event = {wheel_rail_ ? "wheel contact" : "contact", k.rate, EventKind::Kink};  // (with damping the force jumps: IDA finds that and restarts)
      return true;
    case Mode::Contact:
      if (index == 0) {
        st.mode = Mode::Open;
        event = {wheel_rail_ ? "wheel lift-off" : "separation", k.rate, EventKind::Kink};
      } else if (index == 1) {
        st.mode = Mode::Released;
        event = {wheel_rail_ ? "wheel unloaded (damper would pull)" : "released (damper would pull)", k.penetration, EventKind::Kink};
      } else {
        st.segment = 1 - st.segment;
        event = {st.segment == 1 ? "above breakpoint" : "below breakpoint", k.penetration, EventKind::Kink};
      }
      return true;
    case Mode::Released:
      if (index == 0) {
        st.mode = Mode::Open;
        event = {wheel_rail_ ? "wheel lift-off" : "separation", k.rate, EventKind::Kink};
      } else {
        st.mode = Mode::Contact;
        st.segment = k.penetration > breakpoint ? 1 : 0;
        event = {wheel_rail_ ? "wheel contact" : "contact", k.penetration, EventKind::Kink};
      }
      return true;
  }
  return false;
}

SurfaceContact::State SurfaceContact::stiffest_mode(const ElementState<double>& /*s*/) const {
  return State{Mode::Contact, stiffness_above > stiffness ? 1 : 0};
}

double SurfaceContact::potential_energy(const ElementState<double>& s) const {
  const State& st = mode_as<State>(s);
  if (st.mode != Mode::Contact) return 0.0;
  const double d = kinematics(s).penetration;
  if (st.segment == 0) return 0.5 * stiffness * d * d;
  const double above = d - breakpoint;
  return 0.5 * stiffness * breakpoint * breakpoint + stiffness * breakpoint * above + 0.5 * stiffness_above * above * above;
}

void SurfaceContact::outputs(const ElementState<double>& s, const double*, double* out) const {
  const State& st = mode_as<State>(s);
  const Kinematics<double> k = kinematics(s);
  const double normal = st.mode == Mode::Contact ? normal_force(k.penetration, k.rate, st.segment) : 0.0;
  out[0] = normal;
  out[1] = friction > 0.0 ? -friction * normal * std::tanh(k.slip / friction_velocity) : 0.0;
  out[2] = k.penetration;
}

namespace {

/// The normal law and friction both contact types take.
std::vector<ParameterSpec> contact_law_specs(std::vector<ParameterSpec> surface) {
  std::vector<ParameterSpec> all{
      {"stiffness", Unit::ForcePerLength, required, Range::Positive, "normal stiffness k1 (wheel_rail: below breakpoint)"},
      {"damping", Unit::ForceTimePerLength, default_value(0.0), Range::NonNegative,
       "normal damping c (the force never pulls)"},
      {"friction", Unit::Dimensionless, default_value(0.0), Range::NonNegative, "friction coefficient mu"},
      {"friction_velocity", Unit::Velocity, default_velocity(0.01), Range::Positive,
       "slip speed over which the friction builds up (tanh(v_t / friction_velocity))"}};
  all.insert(all.end(), surface.begin(), surface.end());
  return all;
}

}  // namespace

void register_contact_elements(ElementRegistry& registry) {
  registry.add(
      {"contact", "", 1, "P1: the body point that touches the fixed surface",
       "Unilateral contact of a body point with a fixed line or circle: normal force N = k d + c d' while "
       "N >= 0 (d the penetration), friction -mu N tanh(v_t / friction_velocity); contact, lift-off and "
       "release are events.",
       contact_law_specs(
           {{"line_point", Unit::Position, optional("give circle_center instead"), Range::Any,
             "a point of the line surface", Shape::Pair},
            {"line_normal", Unit::Direction, optional("none; a line needs it"), Range::Any,
             "normal of the line, pointing to the free side", Shape::Pair},
            {"circle_center", Unit::Position, optional("give line_point instead"), Range::Any,
             "centre of the circle surface", Shape::Pair},
            {"circle_radius", Unit::Length, optional("none; a circle needs it"), Range::Positive,
             "radius of the circle surface"},
            {"inside", Unit::Choice, default_flag(false), Range::Any,
             "true: the point moves inside the circle (a concave surface)", Shape::Flag}}),
       "stiffness: 1.0e6\ndamping: 100\nfriction: 0.3\nline_point: [0, -1]\nline_normal: [0, 1]",
       [](ElementSpec& s) { return std::make_unique<SurfaceContact>(s, false); }});
  registry.add(
      {"wheel_rail", "18", 1, "P1: the wheel centre",
       "Wheel on a rail: the wheel centre against the rail line y = rail_height + wheel_radius (normal +y), as `contact` with two "
       "slopes: stiffness below the penetration `breakpoint`, stiffness_above beyond it; friction is the "
       "braking / rolling resistance.",
       contact_law_specs({{"wheel_radius", Unit::Length, required, Range::Positive, "wheel radius"},
                          {"rail_height", Unit::Length, default_value(0.0), Range::Any, "height of the rail head"},
                          {"stiffness_above", Unit::ForcePerLength, optional("stiffness"), Range::Positive,
                           "normal stiffness beyond the breakpoint"},
                          {"breakpoint", Unit::Length, optional("none: one slope"), Range::Positive,
                           "penetration at which stiffness_above takes over"}}),
       "stiffness: 1.0e7\nwheel_radius: 0.45\nrail_height: -1.5\nstiffness_above: 2.0e7\nbreakpoint: 0.001",
       [](ElementSpec& s) { return std::make_unique<SurfaceContact>(s, true); }});
}

}  // namespace railcrash
