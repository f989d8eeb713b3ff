// Type 1 anticlimber (report Table 2, type 15): the interaction of the anticlimbers of two
// impacting car ends. Report Section 3.1: "independent nonlinear force-deformation
// relationships for vertical, horizontal and rotational deformations. The computer program
// internal logic checks at each time step to determine if the anticlimbers are in contact,
// if override occurs, and if the anticlimbers fail in either shear, crushing or bending.
// Vertical, horizontal and torsional loads are all accounted for at the anticlimber face."
//
// ---- Geometry ----------------------------------------------------------------------------
// Point P1 (on body 1) is the centre of body 1's anticlimber face, P2 (on body 2) the
// centre of body 2's. Everything is measured in body 1's frame: e1 = R(theta1) (1, 0) is
// its car axis, n1 = R(theta1) (0, 1) its "up"; d = r2 - r1.
//   facing      +1: body 1's face looks along +e1 (body 2 lies ahead of it), -1: along -e1.
//               Default: the sign of d . e1 in the initial configuration (faces that touch at
//               the start need it given).
//   gap         g = facing (d . e1); the faces touch at g = 0. The model must start with
//               g >= 0 (there is no crush history to start from).
//   horizontal deformation   d_h = -g  (crush, positive when the faces are pressed together)
//   vertical offset          v = d . n1  (face 2 above face 1 > 0).
//   initial_misalignment m (report Table 9, P9: "a slight misalignment of the anticlimbers")
//               with misalignment_geometry: face (default, issue 40): face 2's centre is m
//               above point P2 along body 2's +y axis, i.e. P2 + (0, m) in body 2's frame is
//               the point used everywhere above (r2, the offset v, and where the forces act).
//               Giving both points at the same nominal height with m is then exactly the same
//               model as giving P2 at the face centre with m = 0. The misalignment acts through
//               the line of action of the horizontal force (a couple H m on the car ends, which
//               pitches them and so loads the interlock) and the room left before override.
//               misalignment_geometry: offset (the behaviour before issue 40, a labelled
//               variant): m is only added to v (v = d . n1 + m); the forces act at P2. As the
//               interlock takes v at engagement as its reference (below), a constant m then
//               cancels from every force: m changes nothing until override is near (the
//               report's Table 11 run 9, P9 +20 %, moved R1 by -0.08 % and R2 by -1.48 %
//               with no override, so IITRAIN's misalignment did act on the forces).
//   relative rotation        phi = theta2 - theta1.
// Once the faces engage (below) the ribbed faces interlock at the offset and rotation of that
// moment: vertical deformation d_v = v - v_e and torsional deformation d_t = phi - phi_e.
// interlock_while_unloading (hold | release, default hold): whether the ribbed faces keep
// holding each other vertically and in rotation while the horizontal law unloads from its
// largest crush. The report does not settle it; it is a reading.
//   hold     the interlock acts whenever the faces are engaged (up to separation).
//   release  when the horizontal law leaves plastic loading ("horizontal unloading": d_h' = 0
//            at the largest crush) the interlock lets go: no vertical force, no moment, the
//            faces slide freely; it re-seats when the horizontal law reloads onto its yield
//            line ("horizontal reloading"), taking the offset and rotation of that moment
//            as the new reference (elastic, no offset), exactly as on first contact.
//
// ---- Force laws (each direction on its own, "independent" as the report says) ------------
// Each direction follows a bilinear elastic-plastic law with kinematic hardening: elastic
// slope k_e up to the yield deflection d_y (yield force F_y = k_e d_y), plastic slope k_p
// beyond. The force always lies between the two yield lines
//   upper  F_u(d) =  F_y + k_p (d - d_y),      lower  F_l(d) = -F_y + k_p (d + d_y);
// inside them it is elastic, F = k_e (d - p) with the plastic offset p remembered. Loading
// from zero gives the usual bilinear curve; unloading is elastic with the offset kept.
//   horizontal  H(d_h) >= 0, compression only: the lower line is replaced by H = 0, i.e. the
//               faces separate when d_h falls to the permanent crush p_h. Rupture at
//               d_h = horizontal_rupture_deflection is the crushing failure.
//   vertical    V(d_v), both signs (the ribs hold either way); rupture at
//               |d_v| = vertical_rupture_deflection is the shear failure.
//   torsional   M(d_t), both signs; rupture at |d_t| = torsional_rupture_deflection is the
//               bending failure.
// H, V and M derive from the elastic energy U = H^2/2k_e,h + V^2/2k_e,v + M^2/2k_e,t (in
// each mode) through d_h, d_v, d_t, so the generalized forces are -dU/dq:
//   force on body 2 at P2          F = H facing e1 - V n1          (pushes face 2 away from
//                                                                  face 1, pulls it back to
//                                                                  the interlocked height)
//   force on body 1               -F, applied at the same spatial point r2 (where the faces
//                                  meet), so action and reaction share one line of action and
//                                  angular momentum is conserved. (Applying -F at P1 instead
//                                  would leave the couple d x F unbalanced: with the faces
//                                  offset by v it is H v, not small.)
//   torsional couple               -M on body 2, +M on body 1 (a pure couple).
// Outputs (timeseries columns <element>.<name>): horizontal_force H (compression positive),
// vertical_force V (positive when it pushes face 2 down, i.e. resists d_v > 0), moment M
// (positive when it turns body 2 back, i.e. resists d_t > 0), horizontal_deformation d_h
// (= -gap, also while open), vertical_deformation d_v and torsional_deformation d_t (0 when
// not engaged or while the interlock is released), vertical_offset v, override (0 / 1). All
// three forces are 0 unless engaged; V and M are 0 while the interlock is released.
//
// ---- Modes (history changes only at events) ----------------------------------------------
// contact:
//   open        no force. Leaves when d_h reaches the permanent crush p_h (0 until the
//               structure has yielded): "contact". If the faces do not overlap at that moment
//               (|v| >= face_height) they miss each other: "override" instead.
//   engaged     the three laws act. On entry the vertical and torsional interlock takes the
//               current v and phi as reference (their laws restart elastic with no offset;
//               the ribs re-seat, an earlier plastic set of the ribs is not remembered), the
//               horizontal law continues from its history (p_h, largest crush).
//               Leaves when
//                 - the horizontal force falls to zero (d_h = p_h, faces open): "separation"
//                   -> open; the interlock is released.
//                 - |v| reaches face_height: the faces, each face_height tall and centred at
//                   the points, no longer overlap and slide past each other: "override". This
//                   is checked in every engaged state (with the interlock intact the vertical
//                   law normally stops it; after a shear failure nothing does; a large
//                   initial misalignment leaves less room).
//                 - horizontal rupture: "crushing failure".
//               With interlock_while_unloading: release the engaged state has two phases:
//                 interlocked  the three laws act (from contact, and from each re-seating);
//                 released     from a "horizontal unloading" to the next "horizontal
//                              reloading" (or to separation): only the horizontal law acts;
//                              the vertical and torsional laws give no force and have no
//                              roots (their yield, unloading and rupture cannot happen);
//                              the event is named "horizontal unloading, interlock
//                              released". At "horizontal reloading" the interlock re-seats
//                              ("horizontal reloading, interlock re-seated"): references
//                              v_e, phi_e := v, phi; laws fresh (a failed law stays failed).
//                              An unloading from below the yield line (the law never left
//                              its elastic range) releases nothing. Override detection
//                              stays active in both phases.
//   overridden  terminal: the car ends pass over each other; no force in any direction.
//               override_time() and the output `override` (0/1) tell when / whether.
//   crushed     terminal: the anticlimber / end structure is crushed through; no force.
// each law (in the engaged state):
//   elastic [lo, hi]   F = k_e (d - p); lo, hi are where the elastic line meets the yield
//                      lines (lo = p for the horizontal law: separation).
//                      Leaves at d = hi ("yield", or "reloading" once it has yielded before),
//                      d = lo (two-sided: "yield"/"reloading" downwards; horizontal:
//                      separation) or |d| = rupture.
//   plastic up         F = F_u(d); leaves when d' falls to 0 ("unloading": elastic with
//                      hi = d, lo = d - 2 d_y (horizontal: lo = p), p = d - F_u(d)/k_e) or at
//                      |d| = rupture.
//   plastic down       F = F_l(d) (vertical, torsional only); mirror image.
//   failed             F = 0 for good: "crushing failure" (horizontal; the element becomes
//                      crushed), "shear failure" (vertical: the faces no longer hold each
//                      other vertically, only override is left to happen), "bending failure"
//                      (torsional). Failures are permanent damage: they outlast a separation.
// Root functions (11, positive inside the mode): 0-2 horizontal law, 3-5 vertical law, 6-8
// torsional law (each: upper bound / unloading rate, lower bound / unloading rate, rupture),
// 9 contact (open: p_h - d_h), 10 override (engaged: face_height - |v|). An elastic law's bound
// (yield, reloading, the horizontal release) is crossed only while its deformation moves on to
// it (position_root_moving_on, hybrid.hpp; at rest the position alone). A commit re-checks
// the root in the current mode (an earlier commit of the same step may have changed it) and
// then applies every transition whose root is already negative (explicit Euler sees roots
// only at the end of a step, possibly past several boundaries), listing them all in one event.
// A start with the faces just touching (gap 0) is engaged if they are closing, open otherwise.
//
// Energy: the elastic energy above (zero when not engaged; only the horizontal term while the
// interlock is released); the rest of the work done on the element is dissipated (plastic
// flow, and the elastic energy lost at a rupture, a separation, an override or a release of
// the interlock).
//
// Response R2 (report Section 4.1): R2 = max |vertical_force| / vertical yield force, the
// latter vertical_elastic_stiffness * vertical_yield_deflection (vertical_yield_force()).
// The maximum is taken over the output samples of `vertical_force` (as IITRAIN took it over
// its time steps); within plastic flow |V| grows monotonically, so a peak there is the value
// at the following "vertical unloading" or "shear failure" event.
//
// ---- Parameters (report Table 5, repeated in Table 8; names as there) ----------------------
// The scanned tables are garbled: the labels and the "= value" cells come in separate runs.
// Matching them in order (both ends K and L list the same values) gives, per car end:
//   vertical_elastic_stiffness     175,000 lb/in      vertical_plastic_stiffness    1633 lb/in
//   vertical_yield_deflection      0.20 in            vertical_rupture_deflection   5 in
//   horizontal_elastic_stiffness   4,450,000 lb/in    horizontal_plastic_stiffness  20,620 lb/in
//   horizontal_yield_deflection    0.053 in           horizontal_rupture_deflection 56 in
//   torsional_elastic_stiffness    110,800 in-lb/rad  torsional_plastic_stiffness   25,500 in-lb/rad
//   torsional_yield_deflection     0.001 rad          torsional_rupture_deflection  1 rad
//   face_height                    6 in               length                        58.125 in
// (The horizontal rupture cell is unlabelled in the scan, between "Horizontal yield
// deflection" = 0.053 in and "Torsional elastic stiffness" = 110,800: it is the only place
// left for the 56 in.) Typical yield forces: vertical 35,000 lb, horizontal 235,850 lb.
// The element takes one law for the pair of faces. The report lists one set per car end;
// two identical ends in series act as one law with half the slopes, twice the yield and
// rupture deflections and the same yield force; the report does not say which IITRAIN used.
// `length`: read as the longitudinal length of the anticlimber / end-sill structure the
// element stands for (the report does not define it; its horizontal rupture deflection, 56 in,
// nearly equals the 58.125 in length). It bounds the crush: horizontal_rupture_deflection
// must not exceed it, and defaults to it when only length is given.
#pragma once

#include <optional>
#include <string>

#include "railcrash/elements/hybrid.hpp"
#include "railcrash/model/element.hpp"
#include "railcrash/model/element_registry.hpp"

namespace railcrash {

/// A bilinear elastic-plastic law with kinematic hardening (one direction of the anticlimber).
struct ElasticPlasticLaw {
  double elastic_stiffness = 0.0;  // [force/length] or [moment/rad]
  double plastic_stiffness = 0.0;  // [force/length] or [moment/rad], below elastic_stiffness
  double yield_deflection = 0.0;   // [length] or [rad]
  std::optional<double> rupture_deflection;  // [length] or [rad]; none: never ruptures
  bool one_sided = false;          // compression only (horizontal): the lower bound is F = 0

  enum class Mode { Elastic, PlasticUp, PlasticDown, Failed };
  struct State {
    Mode mode = Mode::Elastic;
    double offset = 0.0;  // p: deformation at zero force in the elastic mode
    double lower = 0.0;   // lo: elastic range [lo, hi]
    double upper = 0.0;   // hi
    bool yielded = false; // has flowed plastically before
  };
  /// What leaving a mode through a root did.
  enum class Outcome { Yield, Reloading, Unloading, Rupture, Release };

  double yield_force() const { return elastic_stiffness * yield_deflection; }
  /// Elastic, no plastic offset.
  State fresh() const;

  template <class T>
  T force(const State& st, const T& d) const {
    switch (st.mode) {
      case Mode::Elastic: return elastic_stiffness * (d - st.offset);
      case Mode::PlasticUp: return yield_force() + plastic_stiffness * (d - yield_deflection);
      case Mode::PlasticDown: return -yield_force() + plastic_stiffness * (d + yield_deflection);
      case Mode::Failed: break;
    }
    return T(0.0);
  }
  /// The three roots of the mode at deformation d moving at rate (inactive: 1).
  void roots(const State& st, double d, double rate, double* g) const;
  /// True when root `index` (0..2) belongs to the mode.
  bool active(const State& st, int index) const;
  /// Leaves the mode through root `index` at deformation d.
  Outcome leave(State& st, int index, double d) const;
  /// Energy stored in the elastic part at d.
  double elastic_energy(const State& st, double d) const;
};

class Anticlimber : public HybridElement<Anticlimber> {
 public:
  explicit Anticlimber(ElementSpec& spec);

  ElasticPlasticLaw horizontal;  // d_h [length], H [force]
  ElasticPlasticLaw vertical;    // d_v [length], V [force]
  ElasticPlasticLaw torsional;   // d_t [rad], M [moment]
  double face_height;            // [length] height of each face (override when |v| >= it)
  std::optional<double> length;  // [length] of the crushable structure (bounds the crush)
  double initial_misalignment;   // [length] vertical offset of face 2 above face 1 added to the geometry
  bool misalignment_at_face = true;  // misalignment_geometry: face (true) or offset (false)
  std::optional<double> facing;  // +1 / -1: body 1's face looks along +e1 / -e1 (default: from the start)
  bool release_while_unloading = false;  // interlock_while_unloading: release (true) or hold (false)

  enum class Contact { Open, Engaged, Overridden, Crushed };
  struct State {
    Contact contact = Contact::Open;
    ElasticPlasticLaw::State horizontal, vertical, torsional;
    double vertical_reference = 0.0;   // [length] v at engagement
    double torsional_reference = 0.0;  // [rad] phi at engagement
    double override_time = -1.0;       // [time] of the override; < 0: none
    bool interlock_released = false;   // release: between horizontal unloading and reloading
  };
  RAILCRASH_ELEMENT_MODE(State, initial_state_)

  static bool overridden(const State& st) { return st.contact == Contact::Overridden; }
  /// Denominator of the report's response R2 [force].
  double vertical_yield_force() const { return vertical.yield_force(); }
  /// True while the vertical and torsional laws act (engaged and not released).
  static bool interlocked(const State& st) { return st.contact == Contact::Engaged && !st.interlock_released; }

  /// Geometry of the faces (see the header comment).
  template <class T>
  struct Kinematics {
    Vec2<T> e1, n1;   // body 1's axes
    Vec2<T> arm1;     // r2 - (x1, y1): from body 1's centre of mass to face 2's centre
    T horizontal;     // d_h = -gap
    T vertical;       // v
    T rotation;       // phi
  };
  template <class T>
  Kinematics<T> kinematics(const ElementState<T>& s) const {
    const PointRef& p1 = point(0);
    const PointRef& p2 = point(1);
    const Pose<T>& q1 = s.q[slot1()];
    const Pose<T>& q2 = s.q[slot2()];
    const Rotation<T>& rotation1 = s.rotation[slot1()];
    Kinematics<T> k;
    k.e1 = rotate(rotation1, 1.0, 0.0);
    k.n1 = rotate(rotation1, 0.0, 1.0);
    const Vec2<T> r2 = point_position(q2, s.rotation[slot2()], p2.sx, face2_sy());
    const Vec2<T> d = r2 - point_position(q1, rotation1, p1.sx, p1.sy);
    k.arm1 = r2 - Vec2<T>{q1.x, q1.y};
    k.horizontal = -(*facing) * dot(d, k.e1);
    k.vertical = dot(d, k.n1) + (misalignment_at_face ? 0.0 : initial_misalignment);
    k.rotation = q2.theta - q1.theta;
    return k;
  }

  template <class T>
  void force_law(double /*t*/, const ElementState<T>& s, std::array<Pose<T>, 2>& f) const {
    const State& st = mode_as<State>(s);
    if (st.contact != Contact::Engaged) return;
    const Kinematics<T> k = kinematics(s);
    const T h = horizontal.force(st.horizontal, k.horizontal);
    T v(0.0), m(0.0);
    if (!st.interlock_released) {
      v = vertical.force(st.vertical, k.vertical - st.vertical_reference);
      m = torsional.force(st.torsional, k.rotation - st.torsional_reference);
    }
    const T push = h * (*facing);
    const Vec2<T> force{push * k.e1.x - v * k.n1.x, push * k.e1.y - v * k.n1.y};
    const PointRef& p2 = point(1);
    add_point_force(s.rotation[slot2()], p2.sx, face2_sy(), force, f[slot2()]);
    Pose<T>& f1 = f[slot1()];
    f1.x -= force.x;
    f1.y -= force.y;
    f1.theta -= cross(k.arm1, force);
    f[slot2()].theta -= m;
    f1.theta += m;
  }

  static constexpr int kHorizontalRoots = 0;  // 0..2
  static constexpr int kVerticalRoots = 3;    // 3..5
  static constexpr int kTorsionalRoots = 6;   // 6..8
  static constexpr int kContactRoot = 9;
  static constexpr int kOverrideRoot = 10;
  static constexpr int kRootCount = 11;

  bool applies_moment() const override { return true; }
  /// Engaged, elastic and interlocked in all three directions, whatever the mode: faces that
  /// start apart have no stiffness at t = 0, and Euler's stability limit must see the
  /// stiffness they will meet with (without it, a 1e9 N/m face between 1 t car ends ran
  /// above its limit).
  State stiffest_mode(const ElementState<double>& s) const;
  void initialize(const ElementState<double>& initial) override;
  int root_count() const override { return kRootCount; }
  void roots_in(const State& st, const ElementState<double>& s, double* g) const;
  bool commit_in(State& st, int index, int direction, double t, const ElementState<double>& s, Event& event) const;
  double potential_energy(const ElementState<double>& s) const override;
  std::vector<std::string> output_names() const override {
    return {"horizontal_force",      "vertical_force",         "moment",          "horizontal_deformation",
            "vertical_deformation", "torsional_deformation", "vertical_offset", "override"};
  }
  /// The horizontal law is the car ends' crush and contact; the vertical one, the interlock.
  std::vector<RoleOfOutput> output_roles() const override {
    return {{OutputRole::Crush, "horizontal_deformation"},
            {OutputRole::ContactForce, "horizontal_force"},
            {OutputRole::VerticalInterlockForce, "vertical_force"},
            {OutputRole::CrashForce, "horizontal_force"},
            {OutputRole::CrashDeformation, "horizontal_deformation"}};
  }
  void outputs(const ElementState<double>& s, const double* lambda, double* out) const override;

 private:
  std::size_t slot1() const { return static_cast<std::size_t>(point_slot(0)); }
  std::size_t slot2() const { return static_cast<std::size_t>(point_slot(1)); }
  /// Body 2's y coordinate of face 2's centre: P2's, raised by the misalignment when it is
  /// geometric (misalignment_geometry: face).
  double face2_sy() const { return point(1).sy + (misalignment_at_face ? initial_misalignment : 0.0); }
  /// Deformations and their rates at s in mode st (vertical / torsional relative to the
  /// engagement references).
  struct Deformations {
    double d[3];      // d_h, d_v, d_t
    double rate[3];   // their rates
    double offset;    // v
    double rotation;  // phi
  };
  Deformations deformations(const State& st, const ElementState<double>& s) const;
  void roots_of(const State& st, const Deformations& k, double* g) const;
  bool active(const State& st, int index) const;
  /// Takes the current offset and rotation as the interlock's reference (fresh laws).
  void seat_interlock(State& st, const Deformations& k) const;
  /// Leaves mode st through root `index`; appends what happened to `what`.
  void transition(State& st, int index, double t, const Deformations& k, std::string& what) const;
  /// Applies every transition whose root is already negative.
  void settle(State& st, double t, const ElementState<double>& s, std::string& what) const;

  State initial_state_;  // the mode a run starts in (from the initial configuration)
};

/// The element as an anticlimber, or nullptr when its type is another (is_anticlimber_type).
inline const Anticlimber* as_anticlimber(const Element& element) {
  return is_anticlimber_type(element.type()) ? &dynamic_cast<const Anticlimber&>(element) : nullptr;
}

}  // namespace railcrash
