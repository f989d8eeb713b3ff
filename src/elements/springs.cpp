#include "railcrash/elements/springs.hpp"

#include <cmath>
#include <cstdio>
#include <string>

#include "railcrash/core/error.hpp"
#include "railcrash/model/element_registry.hpp"

namespace railcrash {

void require_direction(const Element& e, const ElementState<double>& initial) {
  if (line_geometry(e, initial).length == 0.0)
    throw InputError(e.where().prefix() + e.type() + " '" + e.name() +
                     "': its two points coincide in the initial configuration, so it has no direction; move them apart" +
                     (e.type() == "special_spring" ? " or give it an axis" : ""));
}

void PointsMeet::initialize(const Element& e, const ElementState<double>& initial) {
  const LineGeometry<double> line = line_geometry(e, initial);
  for (std::size_t k = 0; k < 2; ++k) {
    const Rotation<double>& r = initial.rotation[static_cast<std::size_t>(e.point_slot(static_cast<int>(k)))];
    reference_axis_[k] = {(r.cos * line.d.x + r.sin * line.d.y) / line.length,
                          (-r.sin * line.d.x + r.cos * line.d.y) / line.length};
  }
}

double PointsMeet::gap(const Element& e, const ElementState<double>& s, double free_length) const {
  const LineGeometry<double> line = line_geometry(e, s);
  return gap(e, s, free_length, line.d, line.length);
}

double PointsMeet::gap(const Element& e, const ElementState<double>& s, double free_length, const Vec2<double>& d,
                       double length) const {
  const double margin = kFraction * free_length;  // [length]
  bool passed = true;
  for (std::size_t k = 0; k < 2; ++k) {
    const Vec2<double> axis =
        rotate(s.rotation[static_cast<std::size_t>(e.point_slot(static_cast<int>(k)))], reference_axis_[k].x, reference_axis_[k].y);
    passed = passed && dot(d, axis) <= 0.0;
  }
  passed = passed && length < kPassedFraction * free_length;
  return passed ? -length - margin : length - margin;
}

bool PointsMeet::met(const Element& e, const ElementState<double>& s, double free_length, int index, int root,
                     int direction) const {
  const LineGeometry<double> line = line_geometry(e, s);
  const double g = gap(e, s, free_length, line.d, line.length);
  const bool passed = g + kFraction * free_length < 0.0;
  if (!passed && dot(line.d, line.d_rate) > 0.0) return false;  // within the margin, moving apart
  return g < 0.0 || (index == root && direction < 0);
}

void PointsMeet::stop(const Element& e, double t, const ElementState<double>& s, double free_length,
                      const std::string& state, const std::string& advice, const char* what,
                      const char* length_name) const {
  const double length = line_geometry(e, s).length;
  const bool passed = gap(e, s, free_length) + kFraction * free_length < 0.0;
  char where_now[96];
  if (passed) std::snprintf(where_now, sizeof where_now, "its points have passed each other (by %g)", length);
  else std::snprintf(where_now, sizeof where_now, "its points are %g apart", length);
  char text[400];
  std::snprintf(text, sizeof text, "' %s at t = %.6g s%s: %s, of %s of %g, where its force has no direction left. ",
                what, t, state.empty() ? "" : (" (" + state + ")").c_str(), where_now, length_name, free_length);
  throw SolverError(e.where().prefix() + e.type() + " '" + e.name() + text + advice);
}

LinearSpring::LinearSpring(ElementSpec& spec)
    : ForceElement(spec.name, spec.type, spec.points, spec.where),
      stiffness(spec.parameters->value("stiffness")),
      free_length(spec.parameters->number("free_length")) {}

void LinearSpring::initialize(const ElementState<double>& initial) {
  const double length = line_geometry(*this, initial).length;
  if (!free_length) free_length = length;
  if (*free_length > 0.0 && length == 0.0)
    throw InputError(where().prefix() + "linear_spring '" + name() +
                     "': its two points coincide in the initial configuration, so the spring has no direction; "
                     "move the points apart or set free_length: 0");
  if (length > 0.0) points_meet_.initialize(*this, initial);
}

void LinearSpring::roots(double, const ElementState<double>& s, const double*, double* g) const {
  g[0] = *free_length > 0.0 ? points_meet_.gap(*this, s, *free_length) : 1.0;
}

bool LinearSpring::commit(int index, int direction, double t, const ElementState<double>& s, const double*, void*,
                          Event&) const {
  if (*free_length > 0.0 && points_meet_.met(*this, s, *free_length, index, 0, direction))
    points_meet_.stop(*this, t, s, *free_length, "", PointsMeet::kSpringAdvice);
  return false;
}

double LinearSpring::potential_energy(const ElementState<double>& s) const {
  const double stretch = line_geometry(*this, s).length - *free_length;
  return 0.5 * stiffness * stretch * stretch;
}

void LinearSpring::outputs(const ElementState<double>& s, const double*, double* out) const {
  const double deformation = line_geometry(*this, s).length - *free_length;
  out[0] = stiffness * deformation;  // tension positive
  out[1] = deformation;
}

LinearDashpot::LinearDashpot(ElementSpec& spec)
    : ForceElement(spec.name, spec.type, spec.points, spec.where),
      damping(spec.parameters->value("damping")) {}

void LinearDashpot::outputs(const ElementState<double>& s, const double*, double* out) const {
  const LineGeometry<double> g = line_geometry(*this, s);
  const double rate = dot(g.d, g.d_rate) / g.length;
  out[0] = damping * rate;
  out[1] = rate;
}

TorsionalSpring::TorsionalSpring(ElementSpec& spec)
    : ForceElement(spec.name, spec.type, spec.points, spec.where),
      stiffness(spec.parameters->value("stiffness")),
      free_angle(spec.parameters->number("free_angle")) {}

void TorsionalSpring::initialize(const ElementState<double>& initial) {
  if (!free_angle) free_angle = relative_angle(initial);
}

double TorsionalSpring::potential_energy(const ElementState<double>& s) const {
  const double rotation = relative_angle(s) - *free_angle;
  return 0.5 * stiffness * rotation * rotation;
}

void TorsionalSpring::outputs(const ElementState<double>& s, const double*, double* out) const {
  const double rotation = relative_angle(s) - *free_angle;
  out[0] = stiffness * rotation;
  out[1] = rotation;
}

TorsionalDashpot::TorsionalDashpot(ElementSpec& spec)
    : ForceElement(spec.name, spec.type, spec.points, spec.where),
      damping(spec.parameters->value("damping")) {}

void TorsionalDashpot::outputs(const ElementState<double>& s, const double*, double* out) const {
  const double rate = s.v[static_cast<std::size_t>(point_slot(1))].theta - s.v[static_cast<std::size_t>(point_slot(0))].theta;
  out[0] = damping * rate;
  out[1] = rate;
}

void register_spring_elements(ElementRegistry& registry) {
  const std::string two_points = "P1 on body 1, P2 on body 2: the ends";
  registry.add({"linear_spring", "1", 2, two_points,
                "Linear spring along P1-P2: tension T = stiffness (L - free_length), L the distance between the points. "
                "With a free length, its points meeting (within 1e-3 free_length) or passing each other stops the run, "
                "naming it.",
                {{"stiffness", Unit::ForcePerLength, required, Range::NonNegative, "spring rate"},
                 {"free_length", Unit::Length, optional("the initial distance P1-P2"), Range::NonNegative,
                  "length at zero force"}},
                "stiffness: 1000\nfree_length: 0.5",
                [](ElementSpec& s) { return std::make_unique<LinearSpring>(s); }});
  registry.add({"linear_dashpot", "2", 2, two_points,
                "Linear dashpot along P1-P2: tension T = damping L', L' the rate of change of the distance P1-P2.",
                {{"damping", Unit::ForceTimePerLength, required, Range::NonNegative, "damping coefficient"}},
                "damping: 50",
                [](ElementSpec& s) { return std::make_unique<LinearDashpot>(s); }});
  registry.add({"torsional_spring", "3", 2, "P1 on body 1, P2 on body 2 (only their bodies matter)",
                "Rotational spring between the two bodies: moment M = stiffness (theta2 - theta1 - free_angle).",
                {{"stiffness", Unit::MomentPerAngle, required, Range::NonNegative, "rotational spring rate"},
                 {"free_angle", Unit::Angle, optional("the initial theta2 - theta1"), Range::Any,
                  "relative angle theta2 - theta1 at zero moment"}},
                "stiffness: 2000\nfree_angle: 0.1",
                [](ElementSpec& s) { return std::make_unique<TorsionalSpring>(s); }});
  registry.add({"torsional_dashpot", "4", 2, "P1 on body 1, P2 on body 2 (only their bodies matter)",
                "Rotational dashpot between the two bodies: moment M = damping (omega2 - omega1).",
                {{"damping", Unit::MomentTimePerAngle, required, Range::NonNegative, "rotational damping coefficient"}},
                "damping: 20",
                [](ElementSpec& s) { return std::make_unique<TorsionalDashpot>(s); }});
}

}  // namespace railcrash
