#include "railcrash/elements/springs.hpp"

#include <cmath>

#include "railcrash/model/element_registry.hpp"

namespace railcrash {

void require_direction(const Element& e, const ElementState<double>& initial) {
  if (line_geometry(e, initial).length == 0.0)
    throw InputError(e.where().prefix() + e.type() + " '" + e.name() +
                     "': its two points coincide in the initial configuration, so it has no direction; move them apart" +
                     (e.type() == "special_spring" ? " or give it an axis" : ""));
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
                "Linear spring along P1-P2: tension T = stiffness (L - free_length), L the distance between the points.",
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
