// Springs and dashpots (report Table 2, types 1-4).
//
// linear_spring (1)      between points P1 (body 1) and P2 (body 2), length L = |r2 - r1|,
//                         unit vector u = (r2 - r1) / L:
//                           tension  T = stiffness * (L - free_length)
//                           force on P2 = -T u, on P1 = +T u
//                           energy   = stiffness * (L - free_length)^2 / 2
// linear_dashpot (2)      rate L' = u . (r2' - r1'):  T = damping * L'  (force as above)
// torsional_spring (3)   relative angle phi = theta2 - theta1:
//                           moment M = stiffness * (phi - free_angle),
//                           moment on body 2 = -M, on body 1 = +M,  energy = stiffness (phi - free_angle)^2 / 2
// torsional_dashpot (4)  M = damping * (omega2 - omega1)  (moments as above)
//
// A free_length / free_angle left out of the model is taken from the initial configuration.
// The line elements are undefined at L = 0 (no direction); the model must keep the
// points apart (a zero free length spring with coincident points is the one exception:
// its force k (r2 - r1) is used directly). A linear_spring with a free length whose points
// come within 1e-3 free_length of each other, or pass each other, stops the run with a message
// naming it (PointsMeet): its force k L0 there has no direction, and a step that carried P2
// past P1 turned it around.
#pragma once

#include <array>
#include <optional>

#include "railcrash/model/element.hpp"
#include "railcrash/model/element_registry.hpp"

namespace railcrash {

/// Offset r2 - r1 of the element's two points and its rate, in global axes.
template <class T>
struct PointOffset {
  Vec2<T> d, d_rate;
};
template <class T>
PointOffset<T> point_offset(const Element& e, const ElementState<T>& s) {
  const PointRef& p1 = e.point(0);
  const PointRef& p2 = e.point(1);
  const auto k1 = static_cast<std::size_t>(e.point_slot(0));
  const auto k2 = static_cast<std::size_t>(e.point_slot(1));
  return {point_position(s.q[k2], s.rotation[k2], p2.sx, p2.sy) - point_position(s.q[k1], s.rotation[k1], p1.sx, p1.sy),
          point_velocity(s.v[k2], s.rotation[k2], p2.sx, p2.sy) - point_velocity(s.v[k1], s.rotation[k1], p1.sx, p1.sy)};
}

/// Geometry shared by the two-point line elements.
template <class T>
struct LineGeometry {
  Vec2<T> d;  // r2 - r1
  Vec2<T> d_rate;  // r2' - r1'
  T length;
};

template <class T>
LineGeometry<T> line_geometry(const Element& e, const ElementState<T>& s) {
  const PointOffset<T> offset = point_offset(e, s);
  LineGeometry<T> g;
  g.d = offset.d;
  g.d_rate = offset.d_rate;
  g.length = sqrt(dot(g.d, g.d));
  return g;
}

/// A line element needs a direction: throws an InputError naming the element when its two points
/// coincide in the initial configuration.
void require_direction(const Element& e, const ElementState<double>& initial);

/// The points-meet check of a line element that pushes its points apart (crush_spring,
/// draft_gear, linear_spring with a free length, nonlinear_spring, special_spring without an
/// axis): its line of action u = (r2 - r1) / L has no direction at L = 0, and a step that
/// carries P2 past P1 turns the force around. The root is L less a margin; and
/// negative once P2 lies behind P1 along the initial direction P1 -> P2 turned with body 1 AND
/// along it turned with body 2, within half the free length (an explicit step may jump past P1
/// by a good part of a short element: a 2 cm coupler spring by 3 mm). An element that swings
/// round one of its bodies (the SUNDIALS slider-crank's spring, shorter than half its free
/// length, turns past 90 degrees against its crank), or round both far from its points' meeting
/// (a coupling's gear whose car ends part vertically, turned through 90 degrees at 0.9 of its
/// free length), is not taken for one whose points met.
class PointsMeet {
 public:
  static constexpr double kFraction = 1e-3;        // [-] the margin, of the free length
  static constexpr double kPassedFraction = 0.5;   // [-] behind P1 nearer than this, of the free length: passed
  /// What a spring's stop message asks for.
  static constexpr const char* kSpringAdvice =
      "The spring needs a stroke it does not have: keep its points apart (a stiffer spring, its points farther "
      "apart, or a contact or crush element that stops the motion first)";
  /// Takes the initial direction P1 -> P2 in each body's frame (the points apart: require_direction).
  void initialize(const Element& e, const ElementState<double>& initial);
  /// The root: |r2 - r1| less the margin, or -|r2 - r1| - margin once the points have passed
  /// each other [length].
  double gap(const Element& e, const ElementState<double>& s, double free_length) const;
  /// The same from the line r2 - r1 = d of length `length` at state s, already at hand.
  double gap(const Element& e, const ElementState<double>& s, double free_length, const Vec2<double>& d,
             double length) const;
  /// Whether a commit of root `index` (crossing in `direction`) finds the points met: the
  /// points-meet root `root` crossing downwards, or the gap already negative whatever root
  /// fired (a step known at its end alone, Euler's, commits one root per element, and the step
  /// that carries P2 past P1 may cross another of the element's roots first). Never while the
  /// points, within the margin but not past each other, move apart (a spring that starts
  /// there: the start commits every negative root); its root, carried on its boundary, fires
  /// when they close again.
  bool met(const Element& e, const ElementState<double>& s, double free_length, int index, int root, int direction) const;
  /// Stops the run (SolverError): "<file:line: ><type> '<name>' is compressed through the whole
  /// distance between its points at t = ... s (<state>): its points are ... apart, of a
  /// free_length of ..., where its force has no direction left. <advice>" (no parentheses
  /// without a state).
  /// `what` replaces "is compressed through the whole distance between its points" (a crush
  /// zone is "crushed through its whole length"), `length_name` the "free_length" (a beam's
  /// "initial length").
  [[noreturn]] void stop(const Element& e, double t, const ElementState<double>& s, double free_length,
                         const std::string& state, const std::string& advice,
                         const char* what = "is compressed through the whole distance between its points",
                         const char* length_name = "a free_length") const;

 private:
  std::array<Vec2<double>, 2> reference_axis_{};  // [-] initial unit direction P1 -> P2 in body 1's and body 2's frames
};

/// Applies a force F2 at P2 and -F2 at P1.
template <class T>
void apply_line_force(const Element& e, const ElementState<T>& s, const Vec2<T>& force_on_p2,
                      std::array<Pose<T>, 2>& f) {
  const PointRef& p1 = e.point(0);
  const PointRef& p2 = e.point(1);
  const auto k1 = static_cast<std::size_t>(e.point_slot(0));
  const auto k2 = static_cast<std::size_t>(e.point_slot(1));
  add_point_force(s.rotation[k2], p2.sx, p2.sy, force_on_p2, f[k2]);
  add_point_force(s.rotation[k1], p1.sx, p1.sy, Vec2<T>{-force_on_p2.x, -force_on_p2.y}, f[k1]);
}

class LinearSpring : public ForceElement<LinearSpring> {
 public:
  LinearSpring(ElementSpec& spec);
  double stiffness;                  // [force/length]
  std::optional<double> free_length; // [length]

  template <class T>
  void force_law(double /*t*/, const ElementState<T>& s, std::array<Pose<T>, 2>& f) const {
    const LineGeometry<T> g = line_geometry(*this, s);
    // force on P2 = -k (L - L0) u = -k (1 - L0 / L) d
    T scale = (*free_length == 0.0) ? T(stiffness) : stiffness * (1.0 - *free_length / g.length);
    apply_line_force(*this, s, Vec2<T>{-scale * g.d.x, -scale * g.d.y}, f);
  }
  void initialize(const ElementState<double>& initial) override;
  /// One root: the points meeting (PointsMeet), with a free length; 1 without one.
  int root_count() const override { return 1; }
  void roots(double t, const ElementState<double>& s, const double* lambda, double* g) const override;
  /// The points met: stops the run (PointsMeet::stop). Nothing else changes mode.
  bool commit(int index, int direction, double t, const ElementState<double>& s, const double* lambda, void* mode,
              Event& event) const override;
  double potential_energy(const ElementState<double>& s) const override;
  bool conservative(const ElementState<double>& /*s*/) const override { return true; }
  std::vector<std::string> output_names() const override { return {"force", "deformation"}; }
  void outputs(const ElementState<double>& s, const double* lambda, double* out) const override;

 private:
  PointsMeet points_meet_;
};

class LinearDashpot : public ForceElement<LinearDashpot> {
 public:
  LinearDashpot(ElementSpec& spec);
  double damping;  // [force*time/length]

  template <class T>
  void force_law(double /*t*/, const ElementState<T>& s, std::array<Pose<T>, 2>& f) const {
    const LineGeometry<T> g = line_geometry(*this, s);
    // T = c L',  L' = u . d' ; force on P2 = -T u = -c (d . d') d / L^2
    const T scale = damping * dot(g.d, g.d_rate) / (g.length * g.length);
    apply_line_force(*this, s, Vec2<T>{-scale * g.d.x, -scale * g.d.y}, f);
  }
  std::vector<std::string> output_names() const override { return {"force", "rate"}; }
  void outputs(const ElementState<double>& s, const double* lambda, double* out) const override;
};

class TorsionalSpring : public ForceElement<TorsionalSpring> {
 public:
  TorsionalSpring(ElementSpec& spec);
  double stiffness;                 // [moment/rad]
  std::optional<double> free_angle; // [rad] relative angle theta2 - theta1 at zero moment

  template <class T>
  void force_law(double /*t*/, const ElementState<T>& s, std::array<Pose<T>, 2>& f) const {
    const T moment = stiffness * (relative_angle(s) - *free_angle);
    f[slot2()].theta -= moment;
    f[slot1()].theta += moment;
  }
  template <class T>
  T relative_angle(const ElementState<T>& s) const { return s.q[slot2()].theta - s.q[slot1()].theta; }
  std::size_t slot1() const { return static_cast<std::size_t>(point_slot(0)); }
  std::size_t slot2() const { return static_cast<std::size_t>(point_slot(1)); }
  bool applies_moment() const override { return true; }
  void initialize(const ElementState<double>& initial) override;
  double potential_energy(const ElementState<double>& s) const override;
  bool conservative(const ElementState<double>& /*s*/) const override { return true; }
  std::vector<std::string> output_names() const override { return {"moment", "rotation"}; }
  void outputs(const ElementState<double>& s, const double* lambda, double* out) const override;
};

class TorsionalDashpot : public ForceElement<TorsionalDashpot> {
 public:
  TorsionalDashpot(ElementSpec& spec);
  double damping;  // [moment*time/rad]

  template <class T>
  void force_law(double /*t*/, const ElementState<T>& s, std::array<Pose<T>, 2>& f) const {
    const auto k1 = static_cast<std::size_t>(point_slot(0));
    const auto k2 = static_cast<std::size_t>(point_slot(1));
    const T moment = damping * (s.v[k2].theta - s.v[k1].theta);
    f[k2].theta -= moment;
    f[k1].theta += moment;
  }
  bool applies_moment() const override { return true; }
  std::vector<std::string> output_names() const override { return {"moment", "rate"}; }
  void outputs(const ElementState<double>& s, const double* lambda, double* out) const override;
};

}  // namespace railcrash
