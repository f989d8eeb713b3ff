// Constraint elements (report Table 2, types 6-10): algebraic equations Phi(q) = 0 of the
// DAE (multipliers lambda are the reaction forces), or penalty springs under explicit Euler.
// Point P1 is on body 1 (first point), P2 on body 2 (second point); r1, r2 their positions.
//
// pin_joint (6)            r2 - r1 = 0                                    (2 rows: x, y)
// slider_joint (7)         n1 . (r2 - r1) = 0,  theta2 - theta1 - a0 = 0  (2 rows)
//                          body 2 translates along `axis` (a direction in body 1's frame,
//                          n1 = R(theta1) perp(axis) its unit normal) and may not rotate
//                          relative to body 1
// sliding_pin_joint (8)    n1 . (r2 - r1) = 0                             (1 row)
//                          P2 stays on the line through P1 along `axis`; rotation free
// double_slider_joint (9)  theta2 - theta1 - a0 = 0                       (1 row)
//                          relative rotation locked, translation free
// rigid_joint (10)         r2 - r1 = 0,  theta2 - theta1 - a0 = 0         (3 rows)
//
// a0 (`relative_angle`) is the locked relative angle; left out, it is taken from the
// initial configuration. Row sign convention: the reaction on body 2 is -G2^T lambda.
//
// Friction (report: pin joint "friction parameter muR"; slider joint coefficient of friction
// and slider length), Coulomb regularized smoothly below a slip speed v_f: tanh(v / v_f).
//   pin_joint     moment on body 2 = -muR |R| tanh(w_rel / w_f), +that on body 1; |R| the
//                 reaction's magnitude, w_rel = omega2 - omega1; `friction_radius` muR
//                 [length], `friction_velocity` w_f [rad/time] (default 0.01)
//   slider_joint  force on body 2 at P2 along the axis a = R(theta1) axis:
//                 -mu N tanh(v_rel / v_f), the opposite on body 1 at the same place, where
//                 N = sqrt(Rn^2 + (2 M / l)^2) combines the normal reaction Rn and the
//                 moment M of the angle lock carried by the slider's two ends l apart
//                 (`friction` mu, `slider_length` l [length], `friction_velocity` v_f
//                 [length/time], default 0.01 in/s = 2.54e-4 m/s), v_rel the slip of P2 along a
//                 relative to body 1.
// |R| and N are evaluated as sqrt(x^2 + 1e-30) so their derivative exists at zero load.
#pragma once

#include <optional>

#include "railcrash/model/element.hpp"
#include "railcrash/model/element_registry.hpp"

namespace railcrash {

class Joint {
 public:
  /// The constraint's geometry, shared by all joint types.
  template <class T>
  static Vec2<T> separation(const Element& e, const std::array<Pose<T>, 2>& q) {  // r2 - r1
    const PointRef& p1 = e.point(0);
    const PointRef& p2 = e.point(1);
    return point_position(q[static_cast<std::size_t>(e.point_slot(1))], p2.sx, p2.sy) -
           point_position(q[static_cast<std::size_t>(e.point_slot(0))], p1.sx, p1.sy);
  }
  template <class T>
  static T relative_angle(const Element& e, const std::array<Pose<T>, 2>& q) {  // theta2 - theta1
    return q[static_cast<std::size_t>(e.point_slot(1))].theta - q[static_cast<std::size_t>(e.point_slot(0))].theta;
  }
  template <class T>
  static T normal_offset(const Element& e, const std::array<Pose<T>, 2>& q, double axis_x, double axis_y) {
    // n1 = R(theta1) perp(axis), perp(a) = (-a_y, a_x)
    const Vec2<T> normal = rotate(q[static_cast<std::size_t>(e.point_slot(0))].theta, -axis_y, axis_x);
    return dot(normal, separation(e, q));
  }
};

class PinJoint : public ConstraintElement<PinJoint> {
 public:
  static constexpr int kRows = 2;
  explicit PinJoint(ElementSpec& spec);
  double friction_radius = 0.0;    // [length] muR
  double friction_velocity = 0.01; // [rad/time] w_f
  double friction_slip_velocity() const override { return friction_radius > 0.0 ? friction_velocity : 0.0; }
  bool friction_slip_is_angular() const override { return true; }
  template <class T>
  void constraint_law(const std::array<Pose<T>, 2>& q, T* phi) const {
    const Vec2<T> d = Joint::separation(*this, q);
    phi[0] = d.x;
    phi[1] = d.y;
  }
  template <class T>
  void joint_force_law(double, const ElementState<T>& s, const T* lambda, std::array<Pose<T>, 2>& f) const {
    const auto k1 = static_cast<std::size_t>(point_slot(0)), k2 = static_cast<std::size_t>(point_slot(1));
    const T reaction = sqrt(lambda[0] * lambda[0] + lambda[1] * lambda[1] + 1e-30);
    const T moment = friction_radius * reaction * tanh((s.v[k2].theta - s.v[k1].theta) / friction_velocity);
    f[k2].theta -= moment;
    f[k1].theta += moment;
  }
  bool has_joint_force() const override { return friction_radius > 0.0; }
  std::vector<std::string> output_names() const override { return {"reaction_x", "reaction_y"}; }
  void outputs(const ElementState<double>& s, const double* lambda, double* out) const override;
};

/// Joints whose rows may include a locked relative angle.
class AngleLockingJoint {
 protected:
  explicit AngleLockingJoint(std::optional<double> angle) : locked_angle(angle) {}
  void initialize_angle(const Element& e, const ElementState<double>& initial) {
    if (!locked_angle) locked_angle = Joint::relative_angle(e, initial.q);
  }

 public:
  std::optional<double> locked_angle;  // [rad] theta2 - theta1
};

class SliderJoint : public ConstraintElement<SliderJoint>, public AngleLockingJoint {
 public:
  static constexpr int kRows = 2;
  explicit SliderJoint(ElementSpec& spec);
  double axis_x, axis_y;            // unit sliding direction in body 1's frame
  double friction = 0.0;            // [-] mu
  double slider_length = 1.0;       // [length] l
  double friction_velocity = 0.01;  // [length/time] v_f (as read: default_velocity(0.01), one speed in every unit system)
  double friction_slip_velocity() const override { return friction > 0.0 ? friction_velocity : 0.0; }
  template <class T>
  void constraint_law(const std::array<Pose<T>, 2>& q, T* phi) const {
    phi[0] = Joint::normal_offset(*this, q, axis_x, axis_y);
    phi[1] = Joint::relative_angle(*this, q) - *locked_angle;
  }
  template <class T>
  void joint_force_law(double, const ElementState<T>& s, const T* lambda, std::array<Pose<T>, 2>& f) const {
    const auto k1 = static_cast<std::size_t>(point_slot(0)), k2 = static_cast<std::size_t>(point_slot(1));
    const PointRef& p2 = point(1);
    const Vec2<T> r2 = point_position(s.q[k2], s.rotation[k2], p2.sx, p2.sy);
    const Vec2<T> v2 = point_velocity(s.v[k2], s.rotation[k2], p2.sx, p2.sy);
    // Velocity of the material point of body 1 under P2, and the axis in global axes.
    const Vec2<T> arm1{r2.x - s.q[k1].x, r2.y - s.q[k1].y};
    const Vec2<T> v1{s.v[k1].x - s.v[k1].theta * arm1.y, s.v[k1].y + s.v[k1].theta * arm1.x};
    const Vec2<T> axis = rotate(s.rotation[k1], axis_x, axis_y);
    const T slip = dot(axis, v2 - v1);
    const T couple = 2.0 * lambda[1] / slider_length;
    const T normal = sqrt(lambda[0] * lambda[0] + couple * couple + 1e-30);
    const T magnitude = -friction * normal * tanh(slip / friction_velocity);
    const Vec2<T> force{magnitude * axis.x, magnitude * axis.y};
    add_point_force(s.rotation[k2], p2.sx, p2.sy, force, f[k2]);
    f[k1].x -= force.x;
    f[k1].y -= force.y;
    f[k1].theta -= cross(arm1, force);
  }
  bool has_joint_force() const override { return friction > 0.0; }
  bool constraint_row_is_rotational(int row) const override { return row == 1; }
  void initialize(const ElementState<double>& initial) override { initialize_angle(*this, initial); }
  std::vector<std::string> output_names() const override { return {"normal_reaction", "moment", "travel"}; }
  void outputs(const ElementState<double>& s, const double* lambda, double* out) const override;
};

class SlidingPinJoint : public ConstraintElement<SlidingPinJoint> {
 public:
  static constexpr int kRows = 1;
  explicit SlidingPinJoint(ElementSpec& spec);
  double axis_x, axis_y;
  template <class T>
  void constraint_law(const std::array<Pose<T>, 2>& q, T* phi) const {
    phi[0] = Joint::normal_offset(*this, q, axis_x, axis_y);
  }
  std::vector<std::string> output_names() const override { return {"normal_reaction", "travel"}; }
  void outputs(const ElementState<double>& s, const double* lambda, double* out) const override;
};

class DoubleSliderJoint : public ConstraintElement<DoubleSliderJoint>, public AngleLockingJoint {
 public:
  static constexpr int kRows = 1;
  explicit DoubleSliderJoint(ElementSpec& spec);
  template <class T>
  void constraint_law(const std::array<Pose<T>, 2>& q, T* phi) const {
    phi[0] = Joint::relative_angle(*this, q) - *locked_angle;
  }
  bool constraint_row_is_rotational(int) const override { return true; }
  void initialize(const ElementState<double>& initial) override { initialize_angle(*this, initial); }
  std::vector<std::string> output_names() const override { return {"moment"}; }
  void outputs(const ElementState<double>& s, const double* lambda, double* out) const override;
};

class RigidJoint : public ConstraintElement<RigidJoint>, public AngleLockingJoint {
 public:
  static constexpr int kRows = 3;
  explicit RigidJoint(ElementSpec& spec);
  template <class T>
  void constraint_law(const std::array<Pose<T>, 2>& q, T* phi) const {
    const Vec2<T> d = Joint::separation(*this, q);
    phi[0] = d.x;
    phi[1] = d.y;
    phi[2] = Joint::relative_angle(*this, q) - *locked_angle;
  }
  bool constraint_row_is_rotational(int row) const override { return row == 2; }
  void initialize(const ElementState<double>& initial) override { initialize_angle(*this, initial); }
  std::vector<std::string> output_names() const override { return {"reaction_x", "reaction_y", "moment"}; }
  void outputs(const ElementState<double>& s, const double* lambda, double* out) const override;
};

}  // namespace railcrash
