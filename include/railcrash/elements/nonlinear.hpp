// Nonlinear springs and dashpot (report Table 2, types 19, 20 and 21).
//
// All three act along the line between points P1 (body 1) and P2 (body 2), length
// L = |r2 - r1|, unit vector u = (r2 - r1) / L, rate of length L' = u . (r2' - r1'). Each
// follows a piecewise-linear law f(x) in one scalar x; between breakpoints the law is one
// straight line f = a_k + s_k x, and each breakpoint is a mode change with a located event.
//
// nonlinear_spring (19)  x = e = L - free_length  (extension positive), f = tension T:
//     compression branch (e < 0):  T = -preload + compression_stiffness_1 * e     for -compression_breakpoint <= e <= 0
//                                  continues with compression_stiffness_2 beyond -compression_breakpoint
//     extension branch  (e > 0):   T = -preload + extension_stiffness_1 * e       for 0 <= e <= extension_breakpoint
//                                  continues with extension_stiffness_2 beyond extension_breakpoint
//     T is continuous in e. force on P2 = -T u, on P1 = +T u (tension pulls the points together).
//     preload: the compressive force the spring carries at its free length (positive pushes
//     the points apart, as an installed coil spring; negative: a pretensioned spring).
//     Nonlinear elastic, no hysteresis: energy = integral of T de from e = 0.
//     fracture_load: when |T| reaches it the spring breaks (event "fracture"); from then on
//     its force is zero and the energy it stored counts as dissipated.
//     Modes: compression segment 2 | compression segment 1 | extension segment 1 |
//            extension segment 2 | broken.
//
// nonlinear_dashpot (20)  x = L' (extension rate positive), f = tension T, continuous and
//     piecewise linear in L' with the same two-branch shape (no preload):
//       T = damping_compression_1 * L'  for -compression_switch_velocity <= L' <= 0, then damping_compression_2
//       T = damping_extension_1 * L'    for 0 <= L' <= extension_switch_velocity, then damping_extension_2
//     force on P2 = -T u. It stores nothing: all the work done on it is dissipated.
//     Modes: the four segments; the switch velocities (and L' = 0) are root functions on the rate.
//
// special_spring (21)  the report's "special linear spring", a one-sided contact spring.
//     kind: 1 (default) acts in compression: deflection d = free_length - L, and its force
//             P >= 0 pushes the points apart (force on P2 = +P u);
//     kind: 2 acts in tension: d = L - free_length, and P >= 0 pulls the points together
//             (force on P2 = -P u): a slack link, a safety trap or a rebound strap.
//     open   (d < 0):                 P = 0
//     closed (0 <= d <= breakpoint):  P = preload + stiffness_1 * d
//            (d > breakpoint):        P = preload + stiffness_1 * breakpoint + stiffness_2 * (d - breakpoint)
//     axis (optional, [ax, ay] in the frame of P1's body, global when P1 is on ground): the
//     length measure is then s = (r2 - r1) . a instead of L, with a = R(theta_1) axis / |axis|,
//     d = free_length - s (kind 1) or s - free_length (kind 2), and the force acts along a:
//     P2 against a stop plane of body 1 with normal a. s passes through zero and changes sign
//     where L cannot, which the report's property sets need (both have breakpoint = free
//     length: the second stiffness acts once the points have met and passed). The force
//     acts at r2 on both bodies, so it is the exact gradient of the energy.
//     With a preload the force jumps from 0 to the preload at d = 0 (an installed, caged
//     spring: the stop carries loads up to the preload rigidly); the energy
//     (the integral of P dd) stays continuous. Closing and opening are events;
//     fracture_load as above (P reaching it: event "fracture", force zero from then on).
//     Modes: open | segment 1 | segment 2 | broken.
//     The report's "Special spring (Type 1)" and "(Type 2)" of Table 5 are numbered
//     property sets, as are its "Linear spring (Type 1, 2)", "Beam (Type 1-3)" and
//     "Nonlinear spring (Type 1-5)": both are compression contacts (the coupler leveler
//     spring: 5000 / 3,000,000 lb/in, breakpoint 1.25 in, preload 1250 lb, fracture
//     400,000 lb, free length 1.25 in; the coupler-to-end-sill interference: 0 / 175,000
//     lb/in, breakpoint 4.0 in, no preload, fracture 700,000 lb, free length 4.0 in), so
//     both are written with kind: 1 (and an axis: their breakpoints equal their free lengths).
//     kind: 2 is this program's addition (the report does not say what distinguishes its
//     types), the same law acting in tension.
//
// Points meeting: a nonlinear_spring, and a special_spring of kind 1 without an axis, whose
// points come within 1e-3 free_length of each other, or pass each other, stop the run with a
// message naming them (PointsMeet, springs.hpp): along P1-P2 the force has no direction there,
// and a step that carried one point past the other turned it around. Along an axis the
// separation has a sign and the force a direction: no such stop. Nor for a nonlinear_spring
// that pushes nothing in compression (no preload, compression slopes 0: a tension-only tie,
// slack when its points meet), nor for a special_spring of kind 2 (tension only).
//
// Breakpoints may be zero (the report's nonlinear spring type 5 has an extension breakpoint
// of 0 in): the first segment is then empty and the second slope acts from the start. A
// second slope and its breakpoint go together; without them a branch has one slope.
// Neighbouring segments on the same straight line (equal slopes of a continuous law, e.g.
// the report's dashpot with 1180 lb-s/in both ways) are one segment: a breakpoint that is no
// kink raises no event.
//
// Starting exactly on a breakpoint: with a nonzero rate of x the run starts in the segment x
// moves into; with none (at rest, and always for the dashpot, whose x' is an acceleration)
// in the lower segment. A root exactly zero at a (re)start is then committed by the
// integrators' look-ahead (ModeTracker::commit_boundary) when the motion leaves the
// segment, so the element follows the branch the motion actually takes.
//
// Limitations: a mass at rest on a preloaded special spring with a weight below the preload
// chatters between open and closed (the stop is rigid up to the preload, which no
// force element can represent exactly); a dashpot whose two first damping constants differ
// sees an event at every velocity reversal.
#pragma once

#include <array>
#include <cassert>
#include <optional>
#include <string>
#include <vector>

#include "railcrash/elements/hybrid.hpp"
#include "railcrash/elements/springs.hpp"
#include "railcrash/model/element.hpp"
#include "railcrash/model/element_registry.hpp"

namespace railcrash {

/// f(x) = intercept_k + slope_k x on segment k, between breakpoints b_(k-1) and b_k
/// (segment 0 extends to -infinity, the last one to +infinity).
///
/// The lines, breakpoints and integral constants are stored inside the object (at most
/// kMaxSegments segments: the two-branch law has four, the special spring three): the element
/// that holds the law comes from the elements' own pool (src/model/element.cpp), so the numbers read
/// at every residual sit next to the element's other data. Held in std::vectors on the
/// loader's heap they were one more scattered cache line per element and evaluation, and
/// 100 + 100 and 200 + 200-car consists took about a fifth more CPU (bench/HISTORY.md,
/// "Curves inside the element"). The segments' names, read only for events, stay on the heap.
class PiecewiseLinearLaw {
 public:
  static constexpr int kMaxSegments = 4;

  struct Segment {
    double intercept = 0.0;  // [f]
    double slope = 0.0;      // [f/x]
    std::string name;
  };

  PiecewiseLinearLaw() = default;
  /// breakpoints non-decreasing (n values), segments n + 1. Neighbours on the same line
  /// (equal slopes and equal values at their common breakpoint) are merged; at most
  /// kMaxSegments remain.
  PiecewiseLinearLaw(const std::vector<double>& breakpoints, const std::vector<Segment>& segments);

  /// The usual two-branch law: f(0) = value_at_zero, slope_1 up to the breakpoint on
  /// each side, then slope_2; continuous. Branch breakpoints are distances from 0 (>= 0).
  struct Branch {
    double slope_1 = 0.0;
    std::optional<double> slope_2;     // with breakpoint, or neither
    std::optional<double> breakpoint;  // [x] >= 0
  };
  static PiecewiseLinearLaw two_branch(double value_at_zero, const Branch& negative, const std::string& negative_name,
                                       const Branch& positive, const std::string& positive_name);

  int segment_count() const { return count_; }
  /// Segment k's line and name (a copy: for events and tests, not for the force law).
  Segment segment(int k) const { return {intercept_[index(k)], slope_[index(k)], names_[index(k)]}; }
  const std::string& segment_name(int k) const { return names_[index(k)]; }
  bool has_lower(int k) const { return k > 0; }
  bool has_upper(int k) const { return k + 1 < segment_count(); }
  double lower(int k) const {
    assert(has_lower(k));
    return breakpoints_[index(k - 1)];
  }
  double upper(int k) const {
    assert(has_upper(k));
    return breakpoints_[index(k)];
  }
  std::vector<double> breakpoints() const {
    return {breakpoints_.begin(), breakpoints_.begin() + (count_ > 0 ? count_ - 1 : 0)};
  }

  template <class T>
  T value(const T& x, int k) const {
    return intercept_[index(k)] + slope_[index(k)] * x;
  }
  /// Integral of f from 0 to x along the law, using segment k's line at x.
  double integral(double x, int k) const;
  /// The segment holding x; on a breakpoint, the one above it (direction > 0) or below it.
  int segment_at(double x, int direction) const;

 private:
  static std::size_t index(int k) {
    assert(k >= 0 && k < kMaxSegments);
    return static_cast<std::size_t>(k);
  }
  /// Appends a segment (and the breakpoint below it, for all but the first).
  void append(const Segment& segment, double lower_breakpoint);

  int count_ = 0;
  std::array<double, kMaxSegments> intercept_{};           // [f]
  std::array<double, kMaxSegments> slope_{};               // [f/x]
  std::array<double, kMaxSegments - 1> breakpoints_{};     // [x] between segments k and k + 1
  std::array<double, kMaxSegments> integral_constant_{};   // integral = constant_k + intercept_k x + slope_k x^2 / 2
  std::vector<std::string> names_;                         // events only
};

/// Mode of an element that follows a PiecewiseLinearLaw.
struct SegmentMode {
  int segment = 0;
  bool broken = false;
};

/// Shared hybrid machinery of the line elements below: the law in x = measure(state), the
/// segment roots (0: x - lower breakpoint + band, 1: upper breakpoint - x + band, with band =
/// 1e-14 max(1, largest |breakpoint|) in the unit of x: a segment is left just past its end, so
/// that a state resting exactly on a breakpoint, e.g. a leveler whose points sit exactly at its
/// free length while both bodies move together, is inside a mode rather than on a root that
/// stays at zero; the band stays below what the restart look-ahead of DaeSystem moves),
/// fracture roots (2: fracture_load - f,
/// 3: fracture_load + f, as many as fracture sides) and the mode bookkeeping.
/// A spring that pushes its points apart along P1-P2 (nonlinear_spring; special_spring of kind
/// 1 without an axis) has one more root, the last: its points meeting or passing each other
/// (PointsMeet, springs.hpp), where the run stops naming it.
/// Derived provides
///   double measure(const ElementState<double>&) const;    x
///   int rate_sign(const ElementState<double>&) const;     sign of x', 0 when unknown
///   void prepare(const ElementState<double>& initial);     checks and defaults from the initial configuration
///   Element::Event segment_event(int from, int to, double x) const;
///   double points_meet_length() const;                     the free length for PointsMeet (after prepare)
template <class Derived>
class PiecewiseLineElement : public HybridElement<Derived> {
 public:
  std::optional<double> fracture_load;  // [force]; none: never breaks

  const PiecewiseLinearLaw& law() const { return law_; }
  using State = SegmentMode;
  RAILCRASH_ELEMENT_MODE(SegmentMode, initial_mode_)

  int root_count() const override { return 2 + fracture_roots() + (checks_points_meet() ? 1 : 0); }
  void roots_in(const SegmentMode& m, const ElementState<double>& s, double* g) const;
  bool commit_in(SegmentMode& m, int index, int direction, double t, const ElementState<double>& s,
                 Element::Event& event) const;
  void initialize(const ElementState<double>& initial) override;

  /// Law value f in mode m (0 once broken).
  template <class T>
  T law_value(const SegmentMode& m, const T& x) const {
    return m.broken ? T(0.0) : law_.value(x, m.segment);
  }
  /// x of the state.
  double measure_of(const ElementState<double>& s) const { return static_cast<const Derived*>(this)->measure(s); }
  /// Outputs: the law value f (force) and x.
  void outputs(const ElementState<double>& s, const double* lambda, double* out) const override;
  /// On the law's steepest segment, unbroken, whatever the segment now: a spring that starts
  /// on a soft or open segment (a special spring's gap) meets its steeper ones later, and
  /// Euler's stability limit must see them.
  SegmentMode stiffest_mode(const ElementState<double>& s) const;

 protected:
  /// fracture_sides: 0 (no fracture_load), 1 (f reaching +fracture_load) or 2 (|f|).
  PiecewiseLineElement(ElementSpec& spec, int fracture_sides);
  void set_law(PiecewiseLinearLaw law);
  /// Number of fracture roots (fixed once the constructor has read fracture_load).
  int fracture_roots() const { return fracture_load ? fracture_sides_ : 0; }
  /// Whether the element has the points-meet root (fixed once the constructor has run).
  bool checks_points_meet() const { return checks_points_meet_; }
  /// Gives the element the points-meet root (a derived constructor, before the run).
  void set_points_meet(bool checks) { checks_points_meet_ = checks; }
  /// The points-meet root's index (the last) and value [length]; 1 with a free length of 0.
  int points_meet_root() const { return 2 + fracture_roots(); }
  double points_meet_gap(const ElementState<double>& s) const;
  /// Integral of f dx from x = 0 to the state's x in the current mode (0 once broken): the
  /// elastic energy of the springs.
  double law_integral(const ElementState<double>& s) const;

 private:
  PiecewiseLinearLaw law_;
  double root_band_ = 0.0;  // [unit of x] distance past a breakpoint at which a segment root fires
  SegmentMode initial_mode_;  // the mode a run starts in (from the initial configuration)
  int fracture_sides_ = 0;
  bool checks_points_meet_ = false;  // set_points_meet
  PointsMeet points_meet_;
};

class NonlinearSpring : public PiecewiseLineElement<NonlinearSpring> {
 public:
  explicit NonlinearSpring(ElementSpec& spec);

  PiecewiseLinearLaw::Branch compression;  // slopes [force/length], breakpoint [length]
  PiecewiseLinearLaw::Branch extension;    // slopes [force/length], breakpoint [length]
  double preload = 0.0;                    // [force] compressive force at free length
  std::optional<double> free_length;       // [length]; default: initial length

  template <class T>
  void force_law(double /*t*/, const ElementState<T>& s, std::array<Pose<T>, 2>& f) const {
    const SegmentMode& m = mode_as<SegmentMode>(s);
    if (m.broken) return;
    const LineGeometry<T> g = line_geometry(*this, s);
    const T tension = law_value(m, T(g.length - *free_length));
    const T scale = tension / g.length;  // force on P2 = -T u = -(T / L) d
    apply_line_force(*this, s, Vec2<T>{-scale * g.d.x, -scale * g.d.y}, f);
  }

  double measure(const ElementState<double>& s) const { return line_geometry(*this, s).length - *free_length; }
  double points_meet_length() const { return *free_length; }
  int rate_sign(const ElementState<double>& s) const;
  void prepare(const ElementState<double>& initial);
  Event segment_event(int from, int to, double x) const;

  double potential_energy(const ElementState<double>& s) const override { return law_integral(s); }
  /// Elastic until it breaks; breaking releases (dissipates) the energy it held.
  bool conservative(const ElementState<double>& s) const override { return !mode_as<SegmentMode>(s).broken; }
  std::vector<std::string> output_names() const override { return {"force", "deformation"}; }  // tension positive
};

class NonlinearDashpot : public PiecewiseLineElement<NonlinearDashpot> {
 public:
  explicit NonlinearDashpot(ElementSpec& spec);

  PiecewiseLinearLaw::Branch compression;  // dampings [force*time/length], switch velocity [length/time]
  PiecewiseLinearLaw::Branch extension;    // dampings [force*time/length], switch velocity [length/time]

  template <class T>
  void force_law(double /*t*/, const ElementState<T>& s, std::array<Pose<T>, 2>& f) const {
    const LineGeometry<T> g = line_geometry(*this, s);
    const T rate = dot(g.d, g.d_rate) / g.length;
    const T scale = law_value(mode_as<SegmentMode>(s), rate) / g.length;
    apply_line_force(*this, s, Vec2<T>{-scale * g.d.x, -scale * g.d.y}, f);
  }

  double measure(const ElementState<double>& s) const;
  double points_meet_length() const { return 0.0; }  // (no points-meet root)
  int rate_sign(const ElementState<double>&) const { return 0; }  // x' is an acceleration
  void prepare(const ElementState<double>& initial);
  Event segment_event(int from, int to, double x) const;

  std::vector<std::string> output_names() const override { return {"force", "rate"}; }  // tension positive
};

class SpecialSpring : public PiecewiseLineElement<SpecialSpring> {
 public:
  explicit SpecialSpring(ElementSpec& spec);

  int kind = 1;                       // 1: acts in compression, 2: acts in tension
  // stiffness_1 [force/length] from zero deflection, stiffness_2 [force/length] beyond
  // breakpoint [length] (stiffness_2 and breakpoint together, or neither: one stiffness)
  PiecewiseLinearLaw::Branch closed;
  double preload = 0.0;               // [force] force at zero deflection once closed (>= 0)
  std::optional<double> free_length;  // [length]; default: initial length (or initial s with an axis)
  std::optional<Vec2<double>> axis;   // [-] unit vector in the frame of P1's body (global for ground)

  template <class T>
  void force_law(double /*t*/, const ElementState<T>& s, std::array<Pose<T>, 2>& f) const {
    const SegmentMode& m = mode_as<SegmentMode>(s);
    if (m.broken) return;
    if (axis) {
      // A point (P2) against a stop plane on body 1 with normal a: the force acts along a at r2
      // on both bodies, so it is the exact gradient of the energy (body 1 feels the lever arm r2 - c1).
      const AxisGeometry<T> g = axis_geometry(s);
      const T force = direction() * law_value(m, T(direction() * (*free_length - g.along)));
      const Vec2<T> on_2{force * g.a.x, force * g.a.y};
      const PointRef& p2 = point(1);
      add_point_force(s.rotation[slot_of(1)], p2.sx, p2.sy, on_2, f[slot_of(1)]);
      Pose<T>& body_1 = f[slot_of(0)];
      const Vec2<T> arm = g.r2 - Vec2<T>{s.q[slot_of(0)].x, s.q[slot_of(0)].y};
      body_1.x -= on_2.x;
      body_1.y -= on_2.y;
      body_1.theta -= cross(arm, on_2);
      return;
    }
    const LineGeometry<T> g = line_geometry(*this, s);
    const T force = law_value(m, T(direction() * (*free_length - g.length)));
    // kind 1: force on P2 = +P u; kind 2: -P u
    const T scale = direction() * force / g.length;
    apply_line_force(*this, s, Vec2<T>{scale * g.d.x, scale * g.d.y}, f);
  }
  /// +1 for kind 1 (deflection = shortening), -1 for kind 2 (deflection = lengthening).
  double direction() const { return kind == 1 ? 1.0 : -1.0; }

  /// With an axis: a = R(theta_1) axis, r2, and s = (r2 - r1) . a.
  template <class T>
  struct AxisGeometry {
    Vec2<T> a, r2;
    T along;
  };
  template <class T>
  AxisGeometry<T> axis_geometry(const ElementState<T>& s) const {
    const PointRef& p1 = point(0);
    const PointRef& p2 = point(1);
    AxisGeometry<T> g;
    const Vec2<T> r1 = point_position(s.q[slot_of(0)], s.rotation[slot_of(0)], p1.sx, p1.sy);
    g.r2 = point_position(s.q[slot_of(1)], s.rotation[slot_of(1)], p2.sx, p2.sy);
    g.a = rotate(s.rotation[slot_of(0)], axis->x, axis->y);
    g.along = dot(g.r2 - r1, g.a);
    return g;
  }
  /// Length measure: s along the axis, or the distance L.
  double separation(const ElementState<double>& s) const;

  double measure(const ElementState<double>& s) const { return direction() * (*free_length - separation(s)); }
  double points_meet_length() const { return *free_length; }
  int rate_sign(const ElementState<double>& s) const;
  void prepare(const ElementState<double>& initial);
  Event segment_event(int from, int to, double x) const;

  double potential_energy(const ElementState<double>& s) const override { return law_integral(s); }
  /// Elastic until it breaks; breaking releases (dissipates) the energy it held.
  bool conservative(const ElementState<double>& s) const override { return !mode_as<SegmentMode>(s).broken; }
  // force >= 0 in the working direction (kind 1: compression, kind 2: tension)
  std::vector<std::string> output_names() const override { return {"force", "deflection"}; }

 private:
  std::size_t slot_of(int p) const { return static_cast<std::size_t>(point_slot(p)); }
};

extern template class PiecewiseLineElement<NonlinearSpring>;
extern template class PiecewiseLineElement<NonlinearDashpot>;
extern template class PiecewiseLineElement<SpecialSpring>;

}  // namespace railcrash
