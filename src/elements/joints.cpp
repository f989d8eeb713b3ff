#include "railcrash/elements/joints.hpp"

#include <cmath>

#include "railcrash/element_registry.hpp"

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
  e.penalty.stiffness = spec.parameters->optional_positive("penalty_stiffness");
  e.penalty.damping = spec.parameters->optional_nonnegative("penalty_damping");
  e.penalty.rotational_stiffness = spec.parameters->optional_positive("penalty_rotational_stiffness");
  e.penalty.rotational_damping = spec.parameters->optional_nonnegative("penalty_rotational_damping");
}

template <class J>
std::unique_ptr<Element> make_joint(ElementSpec& spec) {
  auto joint = std::make_unique<J>(spec);
  read_penalty(spec, *joint);
  return joint;
}

}  // namespace

PinJoint::PinJoint(ElementSpec& spec) : ConstraintElement(spec.name, spec.type, spec.points, spec.where) {
  spec.require_points(2);
  friction_radius = spec.parameters->optional_nonnegative("friction_radius").value_or(0.0);
  friction_velocity = spec.parameters->optional_positive("friction_velocity").value_or(0.01);
}

// Reaction on body 2 is -G2^T lambda; for r2 - r1 rows that is (-lambda_x, -lambda_y).
void PinJoint::outputs(const ElementState<double>&, const double* lambda, double* out) const {
  out[0] = -lambda[0];
  out[1] = -lambda[1];
}

SliderJoint::SliderJoint(ElementSpec& spec)
    : ConstraintElement(spec.name, spec.type, spec.points, spec.where),
      AngleLockingJoint(spec.parameters->number("relative_angle")) {
  spec.require_points(2);
  const auto axis = read_axis(spec);
  axis_x = axis[0];
  axis_y = axis[1];
  friction = spec.parameters->optional_nonnegative("friction").value_or(0.0);
  friction_velocity = spec.parameters->optional_positive("friction_velocity").value_or(0.01);
  const auto length = spec.parameters->optional_positive("slider_length");
  if (friction > 0.0 && !length)
    spec.parameters->fail("friction", "a slider_joint with friction needs 'slider_length' (the distance between the "
                                      "slider's bearing ends, which carry the joint's moment)");
  if (length) slider_length = *length;
}

void SliderJoint::outputs(const ElementState<double>& s, const double* lambda, double* out) const {
  const Vec2<double> d = Joint::separation(*this, s.q);
  const Vec2<double> along = rotate(s.q[static_cast<std::size_t>(point_slot(0))].theta, axis_x, axis_y);
  out[0] = -lambda[0];
  out[1] = -lambda[1];
  out[2] = dot(along, d);
}

SlidingPinJoint::SlidingPinJoint(ElementSpec& spec) : ConstraintElement(spec.name, spec.type, spec.points, spec.where) {
  spec.require_points(2);
  const auto axis = read_axis(spec);
  axis_x = axis[0];
  axis_y = axis[1];
}

void SlidingPinJoint::outputs(const ElementState<double>& s, const double* lambda, double* out) const {
  const Vec2<double> d = Joint::separation(*this, s.q);
  const Vec2<double> along = rotate(s.q[static_cast<std::size_t>(point_slot(0))].theta, axis_x, axis_y);
  out[0] = -lambda[0];
  out[1] = dot(along, d);
}

DoubleSliderJoint::DoubleSliderJoint(ElementSpec& spec)
    : ConstraintElement(spec.name, spec.type, spec.points, spec.where),
      AngleLockingJoint(spec.parameters->number("relative_angle")) {
  spec.require_points(2);
}

void DoubleSliderJoint::outputs(const ElementState<double>&, const double* lambda, double* out) const {
  out[0] = -lambda[0];
}

RigidJoint::RigidJoint(ElementSpec& spec)
    : ConstraintElement(spec.name, spec.type, spec.points, spec.where),
      AngleLockingJoint(spec.parameters->number("relative_angle")) {
  spec.require_points(2);
}

void RigidJoint::outputs(const ElementState<double>&, const double* lambda, double* out) const {
  out[0] = -lambda[0];
  out[1] = -lambda[1];
  out[2] = -lambda[2];
}

void register_joint_elements(ElementRegistry& registry) {
  registry.add("pin_joint", make_joint<PinJoint>);
  registry.add("slider_joint", make_joint<SliderJoint>);
  registry.add("sliding_pin_joint", make_joint<SlidingPinJoint>);
  registry.add("double_slider_joint", make_joint<DoubleSliderJoint>);
  registry.add("rigid_joint", make_joint<RigidJoint>);
}

}  // namespace railcrash
