// Couplers and draft gears (report Table 2, types 11-14; Section 3.1 and Figure 11).
//
// Three elements share two building blocks (declared first below):
//   AxialHysteresis  a hysteretic force-deflection law along one axis, used by draft_gear
//                    and by the horizontal law of coupling;
//   DeadBand         a linear spring that acts only outside a band of free play, used by
//                    the faces of coupler_end and the vertical law of coupling.
// Every element is hybrid (element.hpp): between events it is in a fixed mode whose law
// is smooth; every kink or switch is a root function, positive inside the mode, whose
// crossing (IDA: located; Euler: seen at the end of a step) commits the next mode and is
// logged in events.csv. If a commit lands in a mode where another root is already
// negative (crossings that coincide, or an Euler step that went past several), that
// change is applied in the same commit and the event names are joined with ", ".
// Position roots switch kRootBand (1e-12) of the element's size past their boundary, so
// that a model starting exactly on a boundary at rest (faces just touching) is handled.
//
// ---- AxialHysteresis ------------------------------------------------------------------
// Signed deflection u (> 0: buff, compression; < 0: draft, extension), signed force F
// (> 0 pushes the points apart). Total free play `slack` about u = 0; on side sigma
// (+1 buff, -1 draft) the side deflection is x = sigma u - slack / 2 and the side force
// P = sigma F >= 0. Curves of x >= 0, piecewise linear on shared breakpoints:
//   U(x) loading (upper) curve,  Lw(x) <= U(x) unloading (lower) curve,
// and a transition stiffness K_t >= every slope of U and Lw, the elastic line followed
// between the curves after a reversal (so the law stays continuous).
// Modes:
//   open        |u| < slack / 2             F = 0          leaves at x = 0 on a side
//                                                          -> loading (or transition
//                                                          from zero when U(0) > 0)
//   neutral     (U(0) > 0: preloaded,       F = K_t u      leaves when K_t |u| reaches
//                no slack) through u = 0                   U(|u|) -> loading on that side
//   loading     on segment k of U           P = U_k(x)     x' < 0 -> transition; segment
//                                                          ends -> next segment
//   transition  from (x0, P0)               P = P0 + K_t (x - x0)
//                                                          rejoins U going up -> loading;
//                                                          meets Lw going down -> unloading,
//                                                          or P = 0 first -> released (x > 0)
//                                                          or leaves the side; each exit once
//                                                          past its point AND moving that way
//                                                          (x' > 0 up, x' < 0 down). (Where K_t
//                                                          equals a curve's slope the line
//                                                          runs parallel to it: a bottomed
//                                                          gear stays elastic, solid.)
//   unloading   on segment k of Lw          P = Lw_k(x)    x' > 0 -> transition; P = 0
//                                                          (where Lw < 0) -> released;
//                                                          x = 0 (where Lw(0) = 0) -> leaves
//                                                          the side; segment ends
//   released    Lw(x) < 0: the follower     P = 0          x' > 0 -> transition from zero;
//               no longer pushes                           x = 0 -> leaves the side
// Leaving a side: to neutral (preloaded law), to open (slack > 0), otherwise straight to
// loading on the other side (the force passes through zero continuously). A run that
// starts deflected is taken as loaded monotonically to there (loading if still loading,
// else on the transition line from U).
// Stored energy: what unloading from the current state would give back (down the
// transition line to Lw or to zero force, then along Lw to zero force); the rest of the
// work done on the law is dissipated. A closed cycle therefore dissipates its loop area.
//
// ---- DeadBand ---------------------------------------------------------------------------
// Coordinate z, band [lo, hi], stiffness k; the side below and the side above can each be
// switched off. Force f = k (z - lo) < 0 below, 0 inside, k (z - hi) > 0 above; energy
// f^2 / (2 k). Modes below / inside / above, roots at z = lo and z = hi. A band of zero
// width with both sides active is one straight line (below and above meet at lo = hi).
//
// ---- draft_gear (report type 13) --------------------------------------------------------
// Between P1 and P2 (the report's model: the yoke mass and the draft pocket / drawbar mass,
// alongside a slider joint), length L = |r2 - r1|; compression d = free_length - L
// (free_length default: the initial length, the gear at rest).
// A friction draft gear works in buff (d > 0) and, through its yoke, in draft (d < 0): the
// law is AxialHysteresis with u = d, no slack, mirror-symmetric in draft, with
//   U(x)  = S(x) + H,   Lw(x) = S(x) - H,   S(x) = k x (x <= travel), k travel + K (x - travel)
// (k initial_stiffness, K stiffness_after_bottoming, H hysteresis_load: friction-type
// hysteresis; the gear is bottomed beyond `travel`), K_t = transition_stiffness (default K).
// So: at rest the gear is stuck by friction (neutral, F = K_t d) until K_t |d| = U(|d|);
// it then loads on k d + H, bottoms at d = travel (event "bottomed", stiffness K); after a
// reversal it unloads elastically with K_t down to k d - H, follows that line, and once it
// would pull (k d - H < 0) it is "released" (F = 0, never negative in buff) until d = 0,
// where it is "neutral" (stuck) again. Events: "sliding", "bottomed", "off bottom",
// "reversal", "unloading", "reloading", "back on the loading curve", "released" (each
// with " (buff)" or " (draft)"), "neutral"; value: the compression d.
// A cycle 0 -> d_max -> 0 below travel dissipates its loop area, 2 H d_max less the corner
// triangles cut by the neutral and transition lines and by the release at d = H / k.
// Shear pin (buff only: the pin anchors the gear against buff overload): when F reaches
// pin_shear_load ("pin shear") the gear's stored energy is lost and the coupler slides
// freely (F = 0, in either direction) for post_shear_travel; then it is solid,
// F = K (d - d_solid) ("solid", "off solid" if it backs off). Fracture: when |F| reaches
// fracture_load (buff or draft, before or after pin shear) the element carries no force
// from then on ("fracture"). Event value for "pin shear" and "fracture": the force.
// Force on P2 = +F (r2 - r1) / L, on P1 the opposite.
// Points meeting: while the gear carries force (intact, or solid after pin shear), its points
// coming within 1e-3 free_length of each other, or passing each other, stops the run with a
// message naming the element (springs.hpp, PointsMeet): there (r2 - r1) / L has no direction,
// and a step that carried P2 past P1 turned the force around (Euler did so under 540 kN in a
// unit whose gears were shorter than the crush zones beside them: a silent wrong answer). A
// gear that swings round (an unguided coupling whose car ends part vertically) runs on. A
// sheared or fractured gear carries no force, and its points may pass (the report's
// final_two_car: after fracture car1's yoke comes within 1.5e-5 in of its housing's centre
// under IDA, and Euler carries it past).
// Report values (Table 5, repeated in Table 8; they read cleanly in both scans): initial
// stiffness 24,000 lb/in, travel 1.25 in, stiffness after bottoming 320,000 lb/in,
// hysteresis load 10,000 lb, pin shear load 150,000 lb, post-shear travel 1.375 in,
// fracture load 250,000 lb. The report gives no transition stiffness: default K.
//
// ---- coupler_end (report type 14) -------------------------------------------------------
// Contact between two coupler faces; P1 on coupler K, P2 on coupler L, each point
// free_length behind its face (the report's connection points sit 1 in behind the faces).
// The faces are vertical planes (normal: global x): Dx = x2 - x1, Dy = y2 - y1 of the
// points; sigma = side of P2 (sign of Dx at the start; if zero, of the bodies' centres),
// spacing h = sigma Dx, contact spacing c = free_length_K + free_length_L.
//   faces (DeadBand in z = h, k = series of the two horizontal stiffnesses):
//     buff contact h < c: tension T = k (h - c) < 0 (the faces push)
//     coupled: true -> knuckles carry draft once the total horizontal slack s is taken
//       up: T = k (h - c - s) for h > c + s; otherwise no tension ever (and s must be 0).
//   vertical overlap: the faces (heights a_K, a_L, centred on the points) touch only while
//     |Dy| < (a_K + a_L) / 2. Losing the overlap ends the contact ("vertical overlap lost");
//     regaining it with the faces already past each other horizontally gives no force until
//     they are clear again ("blocked" until the band is back inside).
//   friction between the faces: F_t = -mu |T| tanh(Dy' / v_f) on P2 (vertical), Coulomb
//     regularized below friction_velocity v_f; |F_t| <= mu |T|.
//   force on P2 = (-sigma T, F_t), on P1 the opposite. Energy T^2 / (2 k) in contact.
//   restitution e (0 < e <= 1, default 1: the elastic faces above). The report: "The
//     impacting coupler ends were modeled to yield high forces at low deflections. They also
//     included a low coefficient of repercussion to allow for a low force recovery". Read
//     as the coefficient of restitution of the faces' buff contact. With penetration
//     delta = c - h, largest penetration so far delta_max and permanent set
//     p = delta_max (1 - e^2), the buff force P = -T >= 0 is
//       loading     P = k delta                     (the line above; delta grows)
//       unloading   P = k_u (delta - p),  k_u = k / e^2, through (delta_max, k delta_max)
//     so unloading from force P gives back P^2 / (2 k_u) = e^2 P^2 / (2 k): a mass hitting
//     the faces rebounds with e times its speed. The faces keep the set p: contact reopens
//     at delta = p, a later contact starts there on the unloading line, which it follows up
//     to delta_max, then the loading line again. Modes (e < 1; roots positive inside):
//       open        delta < p                       leaves at delta = p: "contact" (onto the
//                                                   loading line if delta_max = 0, else onto
//                                                   the unloading line)
//       loading     P = k delta                     delta' = 0: "unloading" (delta_max = delta)
//       unloading   P = k_u (delta - p)             delta = p: "separation"; delta = delta_max:
//                                                   "reloading" (back on the loading line)
//     The position roots ("contact", "separation", "reloading", and "faces clear" after
//     overlap regained past the set) are crossed only while delta moves on to them
//     (position_root_moving_on, hybrid.hpp; at rest the position alone decides).
//     delta_max (and so p) changes only at these events (and at "vertical overlap lost"
//     while loading). Energy in contact: P^2 / (2 k_u), what unloading would give back; the
//     rest of the work done on the faces is dissipated. With e = 1 there is no unloading
//     mode (k_u = k, p = 0: the faces are elastic and log only "contact" / "separation").
//     Blocked faces (overlap regained past each other) clear at delta = p. Only buff
//     contact has a set: restitution < 1 with coupled: true is an input error (the knuckles'
//     draft law is elastic and a set would shift their slack; the report's coupler ends
//     are uncoupled).
//   shear_load S (force, default none: never): the faces shear off when the buff face force
//     P reaches S: "face shear failure" (value: the force), terminal: no force afterwards in
//     any direction (normal, friction, draft), the stored energy is dissipated. This is the
//     reading of the report's statement that the coupler-end element "accounts for free
//     play, elastic deformation, shear and friction"; the vertical friction force between
//     intact faces is unchanged by it. A start with P >= S is an input error.
// Events: "contact", "separation", "unloading", "reloading" (restitution < 1), "slack taken
// up (draft)", "draft released", "buff to draft" / "draft to buff" (coupled, no slack),
// value h - c; "vertical overlap lost", "vertical overlap regained[, faces past each
// other]", value Dy; "faces clear"; "face shear failure", value P.
// Report values (Tables 5 and 8): horizontal stiffness 360,000 lb/in, free length 1 in and
// coupler height 12 in at each end, total horizontal slack 0.0 in. The "Friction parameter
// (muR) = 0.3" printed under them in Table 8 is the pin joint's (Table 5 lists it under
// "Pin Joint"), so the report gives no face friction: `friction` defaults to 0.
//
// ---- coupling (report types 11 and 12: the freight coupler of the validation runs) ------
// Between a point on each car (P1, P2). Horizontal (global x, sigma as for coupler_end):
// u = free_length - sigma Dx (> 0 buff), free_length = spacing at the centre of the
// horizontal slack (default: the initial spacing). Horizontal force F = AxialHysteresis of
// u with slack = horizontal_slack, mirror-symmetric in draft, U(0) = 0:
//   kind 1 (report type 11): one loading `curve` [[deflection, force], ...] and an
//     `unloading_factor` r (0 <= r <= 1): Lw = r U;
//   kind 2 (report type 12): separate `loading_curve` and `unloading_curve`.
// (The report does not define the two types; this is the documented choice.)
// Vertical: offset of the heads w = Dy + misalignment (misalignment: initial vertical
// offset of the coupler heads when the points are level); DeadBand in w with band
// [-vertical_slack / 2, vertical_slack / 2] and vertical_stiffness: F_v = k_v (w -+ s_v/2).
// Sliding friction between the heads, proportional to the horizontal force:
// F_f = -mu |F| tanh(Dy' / v_f). Force on P2 = (sigma F, -F_v + F_f), on P1 the opposite.
// Energy: the horizontal law's stored energy plus F_v^2 / (2 k_v).
// Events: "slack taken up", "curve segment n", "reversal", "unloading", "reloading", "back
// on the loading curve" (with " (buff)" / " (draft)"), "in the slack", "through zero force
// to buff|draft", value u; "vertical slack taken up (head L above|below)", "vertical
// slack", value w. A coupling without slack that starts at rest at u = 0 takes the
// direction of its first motion.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "railcrash/elements/hybrid.hpp"
#include "railcrash/elements/springs.hpp"
#include "railcrash/model/element.hpp"
#include "railcrash/model/element_registry.hpp"

namespace railcrash {

// ---- shared pieces ------------------------------------------------------------------------

/// Position roots g = (distance to a boundary) + kRootBand x (the element's size): a state
/// exactly on a boundary at rest (a model that starts with its faces just touching) then lies
/// inside its mode, and a departure either way is seen (IDA ignores a root that is exactly
/// zero at the start). The switch happens that far past the boundary: 1e-12 of the size.
constexpr double kRootBand = 1e-12;

/// Piecewise-linear curve y(x), x >= 0: segment j starts at start[j] (start[0] = 0) with
/// value value[j] and slope slope[j]; the last segment goes on without end.
struct PiecewiseLinear {
  std::vector<double> start;  // [length]
  std::vector<double> value;  // [force]
  std::vector<double> slope;  // [force/length]

  /// Through the points (x_0 = 0, x increasing), the last slope extended.
  static PiecewiseLinear through(const std::vector<double>& x, const std::vector<double>& y);
  int segments() const { return static_cast<int>(start.size()); }
  /// Segment holding x (the first one below its start, the last one beyond).
  int segment_of(double x) const;
  template <class T>
  T on_segment(int j, const T& x) const {
    const auto k = static_cast<std::size_t>(j);
    return value[k] + slope[k] * (x - start[k]);
  }
  double at(double x) const { return on_segment(segment_of(x), x); }
  double max_slope() const;
};

/// Hysteretic force-deflection law along one axis (see the header comment).
class AxialHysteresis {
 public:
  PiecewiseLinear upper;          // U(x) [force], loading curve
  PiecewiseLinear lower;          // Lw(x) [force], unloading curve, same breakpoints as upper
  double transition_stiffness = 0.0;  // [force/length] K_t
  double slack = 0.0;             // [length] total free play about u = 0
  double tolerance = 0.0;         // [length] band on the position roots (kRootBand x size)

  enum class Mode { Open, Neutral, Loading, Transition, Unloading, Released };
  struct State {
    Mode mode = Mode::Open;
    int side = 1;       // +1 buff, -1 draft
    int segment = 0;    // loading / unloading: curve segment
    double x0 = 0.0;    // [length] transition: side deflection where it started
    double f0 = 0.0;    // [force] transition: side force there
  };
  /// What a transition did (the elements name it in events.csv).
  enum class Change { Engaged, Sliding, Reversal, OnLowerCurve, Reloading, OnUpperCurve, Released, Centre, SideChange,
                      SegmentUp, SegmentDown };
  static constexpr int kRoots = 4;

  /// True for a preloaded law (U(0) > 0): it has the neutral mode and no slack.
  bool preloaded() const { return upper.value[0] > 0.0; }
  template <class T>
  T side_deflection(const State& st, const T& u) const { return static_cast<double>(st.side) * u - 0.5 * slack; }

  /// Signed force F(u) in mode st (> 0 buff).
  template <class T>
  T force(const State& st, const T& u) const {
    const double sigma = st.side;
    const T x = side_deflection(st, u);
    switch (st.mode) {
      case Mode::Neutral: return transition_stiffness * u;
      case Mode::Loading: return sigma * upper.on_segment(st.segment, x);
      case Mode::Transition: return sigma * (st.f0 + transition_stiffness * (x - st.x0));
      case Mode::Unloading: return sigma * lower.on_segment(st.segment, x);
      case Mode::Open:
      case Mode::Released: break;
    }
    return T(0.0);
  }
  /// |F| in mode st, smooth in the mode: the side force (not |F| in neutral, which only a
  /// preloaded law has; the coupling's law is never preloaded).
  template <class T>
  T magnitude(const State& st, const T& u) const {
    return static_cast<double>(st.side) * force(st, u);
  }

  /// Roots g[0..3] of mode st at deflection u and rate u'.
  void roots(const State& st, double u, double rate, double* g) const;
  /// Applies the change of root `index` (crossed downward) and says what it was.
  Change transition(State& st, int index, double u) const;
  /// Mode at the start of a run at (u, u'): a deflected start is taken as loaded monotonically
  /// to there: loading if still loading, else (at rest or unloading) on the transition line
  /// from the loading curve, which is left either way.
  State initial(double u, double rate) const;
  /// Recoverable energy in mode st at u [force*length].
  double energy(const State& st, double u) const;

 private:
  Change engage(State& st, int side, double u) const;
  Change leave_at_zero(State& st, double u) const;
  Change leave_side(State& st, double u) const;
  /// Where the transition line through (x0, f0) rejoins U going up (first x >= x0 with the
  /// line at or above U; infinity if never), and where it meets Lw going down (last x <= x0
  /// with the line at or below Lw; -infinity if never).
  double rejoin_upper(double x0, double f0) const;
  double rejoin_lower(double x0, double f0) const;
  double unload_from(double x, double force) const;
  double lower_tail(double x) const;
};

/// Linear spring outside a band of free play (see the header comment).
struct DeadBand {
  double lo = 0.0, hi = 0.0;   // [length] band
  double stiffness = 0.0;      // [force/length]
  bool below_active = true, above_active = true;
  double tolerance = 0.0;      // [length] band on the roots (kRootBand x size)

  enum class Mode { Below, Inside, Above };
  static constexpr int kRoots = 2;

  template <class T>
  T force(Mode m, const T& z) const {
    if (m == Mode::Below) return stiffness * (z - lo);
    if (m == Mode::Above) return stiffness * (z - hi);
    return T(0.0);
  }
  /// |force|, smooth in the mode.
  template <class T>
  T magnitude(Mode m, const T& z) const { return m == Mode::Below ? -force(m, z) : force(m, z); }
  void roots(Mode m, double z, double* g) const;
  Mode transition(Mode m, int index) const;
  Mode initial(double z, double rate) const;
  double energy(Mode m, double z) const;
};

// ---- the elements -----------------------------------------------------------------------

class DraftGear : public HybridElement<DraftGear> {
 public:
  explicit DraftGear(ElementSpec& spec);

  double initial_stiffness;           // [force/length] k
  double travel;                      // [length] compression at which the gear bottoms
  double stiffness_after_bottoming;   // [force/length] K
  double hysteresis_load;             // [force] H
  std::optional<double> pin_shear_load;  // [force]; none: no shear pin
  double post_shear_travel = 0.0;     // [length] free travel after pin shear
  std::optional<double> fracture_load;   // [force]; none: never fractures
  double transition_stiffness;        // [force/length] K_t (default K)
  std::optional<double> free_length;  // [length]; default: initial length

  enum class Stage { Intact, Sheared, Solid, Fractured };
  struct State {
    Stage stage = Stage::Intact;
    AxialHysteresis::State law;     // intact
    double solid_compression = 0.0;  // [length] sheared / solid: d at which it goes solid
  };
  RAILCRASH_ELEMENT_MODE(State, initial_state_)
  const AxialHysteresis& law() const { return law_; }

  template <class T>
  void force_law(double /*t*/, const ElementState<T>& s, std::array<Pose<T>, 2>& f) const {
    const State& st = mode_as<State>(s);
    const LineGeometry<T> g = line_geometry(*this, s);
    const T scale = gear_force(st, *free_length - g.length) / g.length;  // force on P2 = F (r2 - r1) / L
    apply_line_force(*this, s, Vec2<T>{scale * g.d.x, scale * g.d.y}, f);
  }
  /// Signed gear force F(d) in mode st (> 0: compression pushes the points apart).
  template <class T>
  T gear_force(const State& st, const T& d) const {
    switch (st.stage) {
      case Stage::Intact: return law_.force(st.law, d);
      case Stage::Solid: return stiffness_after_bottoming * (d - st.solid_compression);
      case Stage::Sheared:
      case Stage::Fractured: break;
    }
    return T(0.0);
  }

  void initialize(const ElementState<double>& initial) override;
  static constexpr int kRoots = AxialHysteresis::kRoots + 3;  // + pin shear, fracture, points meet
  /// The last root, while the gear carries force: its points come within PointsMeet::kFraction of
  /// the free length of each other, or pass each other (the header comment). The run stops there
  /// (SolverError from commit_in).
  static constexpr int kPointsMeetRoot = AxialHysteresis::kRoots + 2;
  /// The points-meet root's value (PointsMeet::gap) [length].
  double points_meet_gap(const ElementState<double>& s) const { return points_meet_.gap(*this, s, *free_length); }
  int root_count() const override { return kRoots; }
  void roots_in(const State& st, const ElementState<double>& s, double* g) const;
  bool commit_in(State& st, int index, int direction, double t, const ElementState<double>& s, Event& event) const;
  State stiffest_mode(const ElementState<double>& s) const;
  double potential_energy(const ElementState<double>& s) const override;
  std::vector<std::string> output_names() const override { return {"force", "compression"}; }
  /// In the crash load path, but not a coupler force: the force between coupler and car body.
  std::vector<RoleOfOutput> output_roles() const override {
    return {{OutputRole::CrashForce, "force"}, {OutputRole::CrashDeformation, "compression"}};
  }
  void outputs(const ElementState<double>& s, const double* lambda, double* out) const override;

 private:
  struct Kinematics {
    double d, rate;  // compression and its rate
  };
  Kinematics kinematics(const ElementState<double>& s) const;
  /// The same from the line geometry at hand.
  Kinematics kinematics_of(const LineGeometry<double>& line) const;
  void roots_at(const State& st, const Kinematics& k, double* g) const;
  void apply(State& st, int index, const Kinematics& k, Event& event) const;

  /// Whether the gear carries force in stage `stage` (its points meeting then stops the run).
  static bool carries_force(Stage stage) { return stage == Stage::Intact || stage == Stage::Solid; }

  AxialHysteresis law_;
  State initial_state_;  // the mode a run starts in (from the initial configuration)
  PointsMeet points_meet_;
};

class CouplerEnd : public HybridElement<CouplerEnd> {
 public:
  explicit CouplerEnd(ElementSpec& spec);

  std::array<double, 2> horizontal_stiffness;  // [force/length] end K, end L
  std::array<double, 2> free_length;           // [length] point to face, end K, end L
  std::array<double, 2> coupler_height;        // [length] face height, end K, end L
  double total_horizontal_slack = 0.0;         // [length] knuckle free play (coupled only)
  double friction = 0.0;                       // [-] mu between the faces
  double friction_velocity = 0.01;             // [length/time] v_f (as read: 0.01 in/s or 2.54e-4 m/s by default)
  double friction_slip_velocity() const override { return friction > 0.0 ? friction_velocity : 0.0; }
  bool coupled = false;                        // knuckles carry draft
  double restitution = 1.0;                    // [-] e of the buff contact, 0 < e <= 1
  std::optional<double> shear_load;            // [force] buff face force at which the faces shear off; none: never

  struct State {
    DeadBand::Mode band = DeadBand::Mode::Inside;  // below: buff contact, above: draft contact
    bool overlapping = true;  // the faces overlap vertically
    bool blocked = false;     // overlap regained with the faces past each other: no force
    bool unloading = false;   // buff contact on the unloading line (restitution < 1)
    double peak = 0.0;        // [length] delta_max, largest buff penetration so far (restitution < 1)
    bool sheared = false;     // the faces have sheared off (terminal)
  };
  RAILCRASH_ELEMENT_MODE(State, initial_state_)
  const DeadBand& faces() const { return faces_; }
  /// +1 when P2 lies in +x of P1 (faces meet along +x), -1 otherwise.
  double side() const { return side_; }
  double series_stiffness() const { return faces_.stiffness; }
  /// k_u = k / e^2 [force/length], the slope of unloading and reloading.
  double unloading_stiffness() const { return faces_.stiffness / (restitution * restitution); }
  /// p = delta_max (1 - e^2) [length], the faces' permanent set in state st.
  double permanent_set(const State& st) const { return st.peak * (1.0 - restitution * restitution); }

  template <class T>
  void force_law(double /*t*/, const ElementState<T>& s, std::array<Pose<T>, 2>& f) const {
    const State& st = mode_as<State>(s);
    if (!active(st)) return;
    const PointOffset<T> o = point_offset(*this, s);
    const T tension = face_tension(st, side_ * o.d.x);
    Vec2<T> on_p2{-side_ * tension, T(0.0)};
    if (friction > 0.0) {
      const T normal = st.band == DeadBand::Mode::Below ? -tension : tension;
      on_p2.y = -friction * normal * tanh(o.d_rate.y / friction_velocity);
    }
    apply_line_force(*this, s, on_p2, f);
  }
  /// Tension T at spacing h in mode st, if the faces are active (< 0: buff).
  template <class T>
  T face_tension(const State& st, const T& h) const {
    if (st.band == DeadBand::Mode::Below && st.unloading)
      return unloading_stiffness() * (h - (faces_.lo - permanent_set(st)));
    return faces_.force(st.band, h);
  }
  bool active(const State& st) const {
    return st.overlapping && !st.blocked && !st.sheared && st.band != DeadBand::Mode::Inside;
  }

  void initialize(const ElementState<double>& initial) override;
  static constexpr int kOverlapRoot = DeadBand::kRoots;
  static constexpr int kShearRoot = DeadBand::kRoots + 1;
  static constexpr int kRoots = DeadBand::kRoots + 2;  // + vertical overlap, face shear
  int root_count() const override { return kRoots; }
  void roots_in(const State& st, const ElementState<double>& s, double* g) const;
  bool commit_in(State& st, int index, int direction, double t, const ElementState<double>& s, Event& event) const;
  State stiffest_mode(const ElementState<double>& s) const;
  double potential_energy(const ElementState<double>& s) const override;
  std::vector<std::string> output_names() const override { return {"normal_force", "friction_force", "gap"}; }
  /// The gap is no deformation: the report shows the force without a loop.
  std::vector<RoleOfOutput> output_roles() const override {
    return {{OutputRole::CouplerForce, "normal_force"}, {OutputRole::CrashForce, "normal_force"}};
  }
  void outputs(const ElementState<double>& s, const double* lambda, double* out) const override;

 private:
  struct Kinematics {
    double h, h_rate, dy, dy_rate;  // spacing along the faces' normal, vertical offset, rates
  };
  Kinematics kinematics(const ElementState<double>& s) const;
  void roots_at(const State& st, const Kinematics& k, double* g) const;
  /// Roots 0, 1 of the faces with restitution < 1 (buff only, with the permanent set).
  void lossy_roots(const State& st, const Kinematics& k, double* g) const;
  void apply(State& st, int index, const Kinematics& k, Event& event) const;
  void apply_lossy(State& st, int index, const Kinematics& k, Event& event) const;
  /// Buff mode at the start or when the overlap is regained (restitution < 1).
  DeadBand::Mode lossy_band(const State& st, const Kinematics& k) const;
  double half_overlap() const { return 0.5 * (coupler_height[0] + coupler_height[1]); }
  bool lossy() const { return restitution < 1.0; }

  DeadBand faces_;
  double side_ = 1.0;
  State initial_state_;  // the mode a run starts in (from the initial configuration)
};

class Coupling : public HybridElement<Coupling> {
 public:
  explicit Coupling(ElementSpec& spec);

  int kind = 1;                       // 1: curve + unloading_factor, 2: loading_curve + unloading_curve
  double horizontal_slack = 0.0;      // [length] total horizontal free play
  double vertical_slack = 0.0;        // [length] total vertical free play of the heads
  double vertical_stiffness = 0.0;    // [force/length] once the vertical slack is taken up
  double misalignment = 0.0;          // [length] vertical offset of head L above head K with the points level
  double friction = 0.0;              // [-] mu between the heads
  double friction_velocity = 0.01;    // [length/time] v_f (as read: 0.01 in/s or 2.54e-4 m/s by default)
  double friction_slip_velocity() const override { return friction > 0.0 ? friction_velocity : 0.0; }
  std::optional<double> free_length;  // [length] spacing at the centre of the slack; default: initial

  struct State {
    AxialHysteresis::State horizontal;
    DeadBand::Mode vertical = DeadBand::Mode::Inside;
  };
  RAILCRASH_ELEMENT_MODE(State, initial_state_)
  const AxialHysteresis& horizontal_law() const { return law_; }
  const DeadBand& vertical_law() const { return vertical_; }
  double side() const { return side_; }

  template <class T>
  void force_law(double /*t*/, const ElementState<T>& s, std::array<Pose<T>, 2>& f) const {
    const State& st = mode_as<State>(s);
    const PointOffset<T> o = point_offset(*this, s);
    const T u = *free_length - side_ * o.d.x;
    const T horizontal = law_.force(st.horizontal, u);
    Vec2<T> on_p2{side_ * horizontal, -vertical_.force(st.vertical, o.d.y + misalignment)};
    if (friction > 0.0)
      on_p2.y = on_p2.y - friction * law_.magnitude(st.horizontal, u) * tanh(o.d_rate.y / friction_velocity);
    apply_line_force(*this, s, on_p2, f);
  }

  void initialize(const ElementState<double>& initial) override;
  static constexpr int kRoots = AxialHysteresis::kRoots + DeadBand::kRoots;
  int root_count() const override { return kRoots; }
  void roots_in(const State& st, const ElementState<double>& s, double* g) const;
  bool commit_in(State& st, int index, int direction, double t, const ElementState<double>& s, Event& event) const;
  State stiffest_mode(const ElementState<double>& s) const;
  double potential_energy(const ElementState<double>& s) const override;
  std::vector<std::string> output_names() const override {
    return {"horizontal_force", "deflection", "vertical_force", "vertical_offset", "friction_force"};
  }
  std::vector<RoleOfOutput> output_roles() const override {
    return {{OutputRole::CouplerForce, "horizontal_force"},
            {OutputRole::CrashForce, "horizontal_force"},
            {OutputRole::CrashDeformation, "deflection"}};
  }
  void outputs(const ElementState<double>& s, const double* lambda, double* out) const override;

 private:
  struct Kinematics {
    double u, u_rate, w, w_rate;  // horizontal deflection, vertical head offset, rates
  };
  Kinematics kinematics(const ElementState<double>& s) const;
  void roots_at(const State& st, const Kinematics& k, double* g) const;
  void apply(State& st, int index, const Kinematics& k, Event& event) const;

  AxialHysteresis law_;
  DeadBand vertical_;
  double side_ = 1.0;
  State initial_state_;  // the mode a run starts in (from the initial configuration)
};

}  // namespace railcrash
