#include "railcrash/elements/joints.hpp"

#include <cmath>

#include "railcrash/model/element_registry.hpp"

namespace railcrash {

namespace {

/// Reads `axis` (default [1, 0]) and normalizes it.
std::array<double, 2> read_axis(ElementSpec& spec) {
  const auto axis = spec.parameters->vector("axis", 2);
  if (!axis) return {1.0, 0.0};
  const double norm = std::hypot((*axis)[0], (*axis)[1]);
  if (!(norm > 0.0)) spec.parameters->fail("axis", "axis must be a non-zero direction [ax, ay]");
  return {(*axis)[0] / norm, (*axis)[1] / norm};
}

void read_penalty(ElementSpec& spec, Element& e) {
  e.penalty().stiffness = spec.parameters->number("penalty_stiffness");
  e.penalty().damping = spec.parameters->number("penalty_damping");
  e.penalty().rotational_stiffness = spec.parameters->number("penalty_rotational_stiffness");
  e.penalty().rotational_damping = spec.parameters->number("penalty_rotational_damping");
}

template <class J>
std::unique_ptr<Element> make_joint(ElementSpec& spec) {
  auto joint = std::make_unique<J>(spec);
  read_penalty(spec, *joint);
  return joint;
}

}  // namespace

PinJoint::PinJoint(ElementSpec& spec) : ConstraintElement(spec.name, spec.type, spec.points, spec.where) {
  friction_radius = spec.parameters->value("friction_radius");
  friction_velocity = spec.parameters->value("friction_velocity");
}

// Reaction on body 2 is -G2^T lambda; for r2 - r1 rows that is (-lambda_x, -lambda_y).
void PinJoint::outputs(const ElementState<double>&, const double* lambda, double* out) const {
  out[0] = -lambda[0];
  out[1] = -lambda[1];
}

SliderJoint::SliderJoint(ElementSpec& spec)
    : ConstraintElement(spec.name, spec.type, spec.points, spec.where),
      AngleLockingJoint(spec.parameters->number("relative_angle")) {
  const auto axis = read_axis(spec);
  axis_x = axis[0];
  axis_y = axis[1];
  friction = spec.parameters->value("friction");
  friction_velocity = spec.parameters->value("friction_velocity");
  const auto length = spec.parameters->number("slider_length");
  if (friction > 0.0 && !length)
    spec.parameters->fail("friction", "a slider_joint with friction needs 'slider_length' (the distance between the "
                                      "slider's bearing ends, which carry the joint's moment)");
  if (length) slider_length = *length;
}

void SliderJoint::outputs(const ElementState<double>& s, const double* lambda, double* out) const {
  const Vec2<double> d = Joint::separation(*this, s.q);
  const Vec2<double> along = rotate(s.rotation[static_cast<std::size_t>(point_slot(0))], axis_x, axis_y);
  out[0] = -lambda[0];
  out[1] = -lambda[1];
  out[2] = dot(along, d);
}

SlidingPinJoint::SlidingPinJoint(ElementSpec& spec) : ConstraintElement(spec.name, spec.type, spec.points, spec.where) {
  const auto axis = read_axis(spec);
  axis_x = axis[0];
  axis_y = axis[1];
}

void SlidingPinJoint::outputs(const ElementState<double>& s, const double* lambda, double* out) const {
  const Vec2<double> d = Joint::separation(*this, s.q);
  const Vec2<double> along = rotate(s.rotation[static_cast<std::size_t>(point_slot(0))], axis_x, axis_y);
  out[0] = -lambda[0];
  out[1] = dot(along, d);
}

DoubleSliderJoint::DoubleSliderJoint(ElementSpec& spec)
    : ConstraintElement(spec.name, spec.type, spec.points, spec.where),
      AngleLockingJoint(spec.parameters->number("relative_angle")) {}

void DoubleSliderJoint::outputs(const ElementState<double>&, const double* lambda, double* out) const {
  out[0] = -lambda[0];
}

RigidJoint::RigidJoint(ElementSpec& spec)
    : ConstraintElement(spec.name, spec.type, spec.points, spec.where),
      AngleLockingJoint(spec.parameters->number("relative_angle")) {}

void RigidJoint::outputs(const ElementState<double>&, const double* lambda, double* out) const {
  out[0] = -lambda[0];
  out[1] = -lambda[1];
  out[2] = -lambda[2];
}

namespace {

/// A joint's declaration: its own parameters, then the Euler penalty overrides every joint takes.
ElementType joint_type(std::string name, std::string report_type, std::string summary,
                       std::vector<ParameterSpec> parameters, std::string example, ElementFactory factory) {
  const Presence from_simulation = optional("the simulation's, else chosen per row by Euler");
  parameters.push_back({"penalty_stiffness", Unit::ForcePerLength, from_simulation, Range::Positive,
                        "Euler: stiffness of the penalty spring that replaces the position rows"});
  parameters.push_back({"penalty_damping", Unit::ForceTimePerLength, from_simulation, Range::NonNegative,
                        "Euler: damping of the penalty spring of the position rows"});
  parameters.push_back({"penalty_rotational_stiffness", Unit::MomentPerAngle, from_simulation, Range::Positive,
                        "Euler: stiffness of the penalty spring that replaces the angle row"});
  parameters.push_back({"penalty_rotational_damping", Unit::MomentTimePerAngle, from_simulation, Range::NonNegative,
                        "Euler: damping of the penalty spring of the angle row"});
  return {std::move(name), std::move(report_type), 2, "P1 on body 1, P2 on body 2: the joined points",
          std::move(summary), std::move(parameters), std::move(example), std::move(factory)};
}

ParameterSpec relative_angle_spec() {
  return {"relative_angle", Unit::Angle, optional("the initial theta2 - theta1"), Range::Any,
          "the locked relative angle theta2 - theta1"};
}

ParameterSpec axis_spec() {
  return {"axis", Unit::Direction, optional("[1, 0]"), Range::Any, "direction of the sliding line in body 1's frame",
          Shape::Pair};
}

ParameterSpec friction_velocity_spec(Unit unit) {
  // A slip speed is the same in both unit systems (0.01 in/s = 2.54e-4 m/s); an angular one, in
  // rad/s, is already.
  return {"friction_velocity", unit, unit == Unit::Velocity ? default_velocity(0.01) : default_value(0.01), Range::Positive,
          "relative speed over which the friction builds up (tanh(v / friction_velocity))"};
}

}  // namespace

void register_joint_elements(ElementRegistry& registry) {
  registry.add(joint_type(
      "pin_joint", "6",
      "P2 = P1 (2 equations); rotation free. Optional joint friction: a resisting moment "
      "friction_radius |reaction| tanh(omega_rel / friction_velocity).",
      {{"friction_radius", Unit::Length, default_value(0.0), Range::NonNegative,
        "friction coefficient times pin radius (muR); 0: no friction"},
       friction_velocity_spec(Unit::AngularVelocity)},
      "friction_radius: 0.01", make_joint<PinJoint>));
  registry.add(joint_type(
      "slider_joint", "7",
      "P2 slides along the axis, theta2 - theta1 locked (2 equations): P2 stays on the line through P1 along the axis "
      "(fixed in body 1). "
      "Optional friction mu sqrt(R_n^2 + (2M/slider_length)^2) tanh(v / friction_velocity) along the axis.",
      {axis_spec(), relative_angle_spec(),
       {"friction", Unit::Dimensionless, default_value(0.0), Range::NonNegative, "friction coefficient mu; 0: none"},
       {"slider_length", Unit::Length, optional("none; needed with friction"), Range::Positive,
        "distance between the slider's bearing ends, which carry the joint's moment"},
       friction_velocity_spec(Unit::Velocity)},
      "axis: [1, 0]\nfriction: 0.1\nslider_length: 0.5", make_joint<SliderJoint>));
  registry.add(joint_type("sliding_pin_joint", "8",
                          "P2 slides along the axis, rotation free (1 equation): P2 stays on the line through P1 along the axis (fixed "
                          "in body 1).",
                          {axis_spec()}, "axis: [0, 1]", make_joint<SlidingPinJoint>));
  registry.add(joint_type("double_slider_joint", "9", "theta2 - theta1 locked; translation free (1 equation).",
                          {relative_angle_spec()}, "relative_angle: 0", make_joint<DoubleSliderJoint>));
  registry.add(joint_type("rigid_joint", "10", "P2 = P1 and theta2 - theta1 locked (3 equations).",
                          {relative_angle_spec()}, "penalty_stiffness: 1.0e6", make_joint<RigidJoint>));
}

}  // namespace railcrash
