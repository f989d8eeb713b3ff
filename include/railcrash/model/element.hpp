// The element interface: what every connecting element (report Table 2) provides.
//
// An element couples at most two bodies ("slots" 0 and 1; a slot may be ground). It never
// touches global storage: it evaluates its law on its local state and the DAE system adds
// the result in (r += F, J += dF/dy + cj dF/dy').
//
// * Force elements (springs, dashpots, ...) give the generalized forces f on their slots,
//   f(t, q, v); their derivatives come from forward-mode AD over the 12 local unknowns.
// * Constraint elements (joints) give m equations Phi(q) = 0 (m <= 3). G = dPhi/dq and the
//   second derivatives needed for d(G^T lambda)/dq come from nested AD of the same Phi code.
//
// Concrete elements derive from ForceElement<Derived> (HybridElement<Derived>, elements/hybrid.hpp,
// for a piecewise law with modes) or ConstraintElement<Derived> and write their law once, as a
// template over the scalar type.
//
// Piecewise laws (contact, yield, unloading, bottoming, rupture, ...) are hybrid: between
// events the element is in a fixed mode and its law is smooth. The element exposes root
// functions g of its current mode; a sign change of one of them means "leave this mode".
// The integrator locates the root (IDA) or sees it at the end of a step (Euler), then calls
// commit(), which changes the mode and its history (plastic offsets, ...). History never
// changes inside a residual evaluation.
//
// Data apart from state (the Model/Data split): an element holds only parameters and
// connection points, immutable once the model is finalized. Its mode and history live in the
// run's ElementStates (model.hpp), one contiguous block with a slot per element; the element
// reads its slot through ElementState::mode and commit() writes into it. A stateful element
// declares its slot type (a trivially copyable struct) with mode_bytes() and
// write_start_mode(), and reads it with mode_as<State>(s).
#pragma once

#include <array>
#include <cassert>
#include <cstddef>
#include <memory>
#include <new>
#include <optional>
#include <type_traits>
#include <string>
#include <vector>

#include "railcrash/core/autodiff.hpp"
#include "railcrash/core/error.hpp"
#include "railcrash/core/planar.hpp"

namespace railcrash {

constexpr int kGround = -1;  // body index of the fixed ground

/// A connection point: a body and an offset from its centre of mass in its own frame.
struct PointRef {
  int body = kGround;
  double sx = 0.0;  // [length] body-fixed offset, body x axis
  double sy = 0.0;  // [length] body-fixed offset, body y axis
};

/// Local state of an element: pose and rate of its two slots (ground slots stay zero), the
/// cos and sin of their angles, and
/// its mode and history (read-only; its slot in the run's ElementStates, null for an element
/// without modes).
template <class T>
struct ElementState {
  std::array<Pose<T>, 2> q{};
  std::array<Pose<T>, 2> v{};
  std::array<Rotation<T>, 2> rotation{};  // cos and sin of q[k].theta, computed once per evaluation
  const void* mode = nullptr;
};

/// The same local state with another mode (e.g. the stiffest one, for a stability estimate).
template <class T, class State>
ElementState<T> in_mode(const ElementState<T>& s, const State& mode) {
  ElementState<T> other = s;
  other.mode = &mode;
  return other;
}

/// The mode and history of a stateful element, State being the type it declared.
template <class State, class T>
const State& mode_as(const ElementState<T>& s) {
  static_assert(std::is_trivially_copyable_v<State>, "element states are copied as bytes (snapshots)");
  assert(s.mode != nullptr);
  return *static_cast<const State*>(s.mode);
}

/// What an element output means to the run summary, `converge`, the responses and the report,
/// so that none of them has to know element types. Each element type declares, next to its
/// output_names(), which of its outputs plays which role (at most one output per role).
enum class OutputRole {
  Crush,                   // [length] crush deformation counted in the crush of its cars (positive part)
  ContactForce,            // [force] horizontal force where two interlocking car ends bear on each other
  CouplerForce,            // [force] horizontal force through a coupler (coupler faces, coupling)
  VerticalInterlockForce,  // [force] vertical force holding two interlocked car ends together
  CrashForce,              // [force] force of an element in the crash load path: y of its force-deformation loop
  CrashDeformation,        // [length] the deformation that force works through: x of the loop
};
constexpr OutputRole kAllOutputRoles[] = {OutputRole::Crush,       OutputRole::ContactForce,
                                          OutputRole::CouplerForce, OutputRole::VerticalInterlockForce,
                                          OutputRole::CrashForce,  OutputRole::CrashDeformation};
/// snake_case name of a role (model.json, summaries): "crush", "contact_force", ...
const char* output_role_name(OutputRole role);

/// One output of an element and the role it plays.
struct RoleOfOutput {
  OutputRole role;
  const char* output;  // one of the element's output_names()
};

using ForceBlock = std::array<std::array<double, 6>, 6>;  // d f(slot, comp) / d (slot, comp)
constexpr int kMaxConstraintRows = 3;

/// The model file's type of the anticlimber (elements/anticlimber.hpp), the element the
/// responses' R2, the scenarios' override criterion and the consists' interfaces are measured
/// at. Every "is this an anticlimber" asks is_anticlimber_type (of a type name, or an element's
/// type()) or as_anticlimber (elements/anticlimber.hpp: the element as one).
inline constexpr const char* kAnticlimberType = "anticlimber";
inline bool is_anticlimber_type(const std::string& type) { return type == kAnticlimberType; }

class Element {
 public:
  Element(std::string name, std::string type, std::vector<PointRef> points, SourceLocation where);
  virtual ~Element() = default;
  Element(const Element&) = delete;
  Element& operator=(const Element&) = delete;
  /// Element objects live side by side in a pool of their own (element.cpp), not among the
  /// loader's allocations: a sweep over a long train's elements then streams through a few
  /// MiB instead of one page per element scattered over the heap the model file's parse left.
  static void* operator new(std::size_t bytes);
  static void operator delete(void* element, std::size_t bytes);
  /// An over-aligned element type (none so far) takes the ordinary aligned heap.
  static void* operator new(std::size_t bytes, std::align_val_t alignment);
  static void operator delete(void* element, std::size_t bytes, std::align_val_t alignment);
  /// False under AddressSanitizer, where elements come from the ordinary heap (so that a use
  /// after free of an element is still caught).
  static bool allocated_from_pool();

  const std::string& name() const { return description_->name; }
  const std::string& type() const { return description_->type; }
  const SourceLocation& where() const { return description_->where; }
  const std::vector<PointRef>& points() const { return description_->points; }

  /// Global body index of slot 0 / 1 (kGround for ground or an unused slot).
  int slot_body(int slot) const { return slot_body_[static_cast<std::size_t>(slot)]; }
  /// Slot holding the body of point p.
  int point_slot(int p) const {
    return p < kNearPoints ? near_point_slot_[static_cast<std::size_t>(p)]
                           : description_->point_slot[static_cast<std::size_t>(p)];
  }
  /// Offset of point p on its body.
  const PointRef& point(int p) const {
    return p < kNearPoints ? near_points_[static_cast<std::size_t>(p)] : description_->points[static_cast<std::size_t>(p)];
  }

  // ---- constraint elements ----
  virtual int constraint_count() const { return 0; }
  /// True when a constraint row is an angle (its penalty stiffness is then a torsional one).
  virtual bool constraint_row_is_rotational(int /*row*/) const { return false; }
  /// Phi(q); phi has constraint_count() entries.
  virtual void constraint(const std::array<Pose<double>, 2>& /*q*/, double* /*phi*/) const {}
  /// Phi and G = dPhi/dq (G[row][3*slot + component]).
  virtual void constraint_gradient(const std::array<Pose<double>, 2>& q, double* phi,
                                   double gradient[kMaxConstraintRows][6]) const;
  /// Phi, G and the second derivatives H[row][i][j] = d^2 Phi_row / dq_i dq_j.
  virtual void constraint_hessian(const std::array<Pose<double>, 2>& q, double* phi,
                                  double gradient[kMaxConstraintRows][6],
                                  double hessian[kMaxConstraintRows][6][6]) const;

  /// Joints with friction also apply forces that depend on their multipliers (reactions).
  virtual bool has_joint_force() const { return false; }
  /// Adds those forces f(t, q, v, lambda) to f.
  virtual void add_joint_force(double /*t*/, const ElementState<double>& /*s*/, const double* /*lambda*/,
                               std::array<Pose<double>, 2>& /*f*/) const {}
  /// The same with derivatives; df_dlambda[3*slot + component][row].
  virtual void add_joint_force_jacobian(double /*t*/, const ElementState<double>& /*s*/, const double* /*lambda*/,
                                        std::array<Pose<double>, 2>& /*f*/, ForceBlock& /*df_dq*/, ForceBlock& /*df_dv*/,
                                        double /*df_dlambda*/[6][kMaxConstraintRows]) const {}

  /// Regularized Coulomb friction, F = -mu N tanh(v / v_f): its v_f when the element has
  /// friction (a slip speed [length/time], or a relative turning rate [rad/time] when
  /// friction_slip_is_angular), else 0. IDA holds the velocities of the element's bodies to a
  /// tenth of it (IdaIntegrator::start), so that its steps resolve which way the friction acts.
  virtual double friction_slip_velocity() const { return 0.0; }
  virtual bool friction_slip_is_angular() const { return false; }

  // ---- force elements ----
  /// Generalized forces on slot 0 and 1 (force x, force y, moment), added to f.
  virtual void add_force(double /*t*/, const ElementState<double>& /*s*/, std::array<Pose<double>, 2>& /*f*/) const {}
  /// The same forces and their derivatives with respect to (q, v) of both slots.
  virtual void add_force_jacobian(double t, const ElementState<double>& s, std::array<Pose<double>, 2>& f,
                                  ForceBlock& df_dq, ForceBlock& df_dv) const;

  // ---- modes and events ----
  /// Number of root functions; fixed for the element's life (an inactive one returns 1).
  virtual int root_count() const { return 0; }
  /// Root functions of the current mode at state s (lambda: the element's multipliers).
  /// Convention: every root is positive inside the mode and the mode is left when a root
  /// falls through zero (commit then gets direction -1). The integrators rely on it at a
  /// (re)start, where a root that is exactly zero and about to fall is committed at once.
  virtual void roots(double /*t*/, const ElementState<double>& /*s*/, const double* /*lambda*/, double* /*g*/) const {}
  /// Whether the element's force stays continuous across a mode change. A kink (crush
  /// unloading or reloading, a curve segment change, contact whose force starts at zero)
  /// changes only the force's slope: IDA goes on without a restart where the lag of its step
  /// allows. A jump (fracture, shear, preloaded contact, a friction reversal, override) changes
  /// the force itself: IDA always restarts from consistent values at the event. IDA checks a
  /// kink's continuity at the event (the element's force before and after the commit) and
  /// restarts where it does not hold.
  enum class EventKind { Jump, Kink };
  /// What happened at an event, for events.csv.
  struct Event {
    std::string what;   // e.g. "contact closed", "yield", "rupture"
    double value = 0.0; // the quantity that triggered it (deformation, force, ...)
    EventKind kind = EventKind::Jump;  // a jump unless the element says its force is continuous
  };
  /// Root `index` changed sign (direction +1: increasing, -1: decreasing) at state s:
  /// commit the mode change into `mode` (the element's slot in the run's ElementStates, the
  /// one s.mode points to). Returns false when the crossing needs no change (the element
  /// may then log nothing).
  virtual bool commit(int /*index*/, int /*direction*/, double /*t*/, const ElementState<double>& /*s*/,
                      const double* /*lambda*/, void* /*mode*/, Event& /*event*/) const {
    return false;
  }
  /// The force Jacobian in the element's stiffest mode at state s, for explicit Euler's
  /// stability limit (an element that starts open has no stiffness at t = 0). Default: the
  /// current mode's.
  virtual void stiffest_force_jacobian(double t, const ElementState<double>& s, ForceBlock& df_dq,
                                       ForceBlock& df_dv) const {
    std::array<Pose<double>, 2> f{};
    add_force_jacobian(t, s, f, df_dq, df_dv);
  }
  /// Size of the element's slot in ElementStates [bytes]; 0 for an element without modes.
  virtual std::size_t mode_bytes() const { return 0; }
  /// Writes the mode the element starts a run in into its slot (mode_bytes() bytes).
  virtual void write_start_mode(void* /*mode*/) const {}
  /// A failed constraint keeps its rows as lambda = 0, mu = 0 (so the pattern never changes);
  /// mode: the element's slot.
  virtual bool failed(const void* /*mode*/) const { return false; }

  // ---- energy and output ----
  /// Energy stored in the element [force*length].
  virtual double potential_energy(const ElementState<double>& /*s*/) const { return 0.0; }
  /// True when the element, in the state's mode, dissipates nothing by construction: its
  /// forces are minus the gradient of potential_energy (an elastic spring, a joint without
  /// friction), so the work done on it and the change of its stored energy differ only by the
  /// integration's error. Its dissipation is then zero and that difference is reported as the
  /// run's integration drift (EnergyBalance). The default, false, is for elements that can
  /// dissipate (dampers, friction, crush, plasticity, fracture): their dissipation is the work
  /// done on them less the change of their stored energy.
  virtual bool conservative(const ElementState<double>& /*s*/) const { return false; }
  /// Names of the quantities this element adds to timeseries.csv (without the element prefix).
  virtual std::vector<std::string> output_names() const { return {}; }
  /// Which of those outputs play which role (OutputRole); most elements have none.
  virtual std::vector<RoleOfOutput> output_roles() const { return {}; }
  /// A surface fixed to the ground that the element's point meets (a wall, a barrier face), for
  /// drawing the scene (model.json, the report's animation); not used by the physics.
  struct GroundSurface {
    enum class Kind { Line, Circle } kind = Kind::Line;
    double x = 0.0, y = 0.0;    // [length] line: a point on it; circle: its centre
    double nx = 0.0, ny = 1.0;  // line: unit normal toward the free side
    double radius = 0.0;        // [length] circle
    bool inside = false;        // circle: the free side is inside it
  };
  /// The element's ground surface, if it has one (the contact element's line or circle).
  virtual std::optional<GroundSurface> ground_surface() const { return std::nullopt; }
  /// The output playing `role`, or "" when the element has none.
  std::string output_with_role(OutputRole role) const;
  /// Values of those quantities; lambda are the element's constraint multipliers (if any).
  virtual void outputs(const ElementState<double>& /*s*/, const double* /*lambda*/, double* /*out*/) const {}
  /// roots() into g and outputs() into out at one state, for the sweeps that want both (either
  /// may be null: that one is skipped). An element whose roots and outputs share an expensive
  /// evaluation overrides this to do it once; the values must equal the two calls', bit for bit.
  virtual void roots_and_outputs(double t, const ElementState<double>& s, const double* lambda, double* g,
                                 double* out) const {
    if (g != nullptr) roots(t, s, lambda, g);
    if (out != nullptr) outputs(s, lambda, out);
  }

  /// add_force(t, s, f) and roots_and_outputs(t, s, lambda, g, out) at one state, for the step
  /// sweeps (the energy rates need the force; g and out may be null). An element whose force,
  /// roots and outputs share an expensive evaluation overrides this to do it once; the values
  /// must equal the separate calls', bit for bit.
  virtual void force_roots_and_outputs(double t, const ElementState<double>& s, const double* lambda,
                                       std::array<Pose<double>, 2>& f, double* g, double* out) const {
    if (g != nullptr || out != nullptr) roots_and_outputs(t, s, lambda, g, out);
    add_force(t, s, f);
  }

  // ---- penalty representation of a constraint (explicit Euler) ----
  struct PenaltyOverrides {
    std::optional<double> stiffness;             // [force/length]
    std::optional<double> damping;               // [force*time/length]
    std::optional<double> rotational_stiffness;  // [moment/rad]
    std::optional<double> rotational_damping;    // [moment*time/rad]
  };
  PenaltyOverrides& penalty() { return description_->penalty; }
  const PenaltyOverrides& penalty() const { return description_->penalty; }

  /// Called by Model::finalize with the global indices of the bodies of each point.
  void bind_bodies();
  /// Called by Model::finalize with the initial state: parameters left "as in the initial
  /// configuration" (free length, free angle, ...) are set here.
  virtual void initialize(const ElementState<double>& /*initial*/) {}
  /// True when the element loads a body with a pure moment (so it needs rotational inertia).
  virtual bool applies_moment() const { return false; }

 protected:
  /// What the sweeps never read: names, the model file's line, all points, penalty overrides.
  /// It lives on the ordinary heap, not in the object, so that the element pool holds only what
  /// a residual, Jacobian or step sweep reads. Those sweeps run through every element at every
  /// evaluation, and their cost per element grows once a long train's elements pass this VM's
  /// 7-8 MiB: 256 unused bytes added to each element made the 200 + 200-car consist's
  /// residual calls 1.8x dearer (bench/HISTORY.md, "Elements without their description").
  struct Description {
    std::string name;
    std::string type;
    std::vector<PointRef> points;
    SourceLocation where;
    std::vector<int> point_slot;  // slot of each point (bind_bodies)
    PenaltyOverrides penalty;
  };
  std::unique_ptr<Description> description_;
  std::array<int, 2> slot_body_{kGround, kGround};
  // Copies of the first points and their slots inside the object, which the laws read at every
  // evaluation: the description lies elsewhere on the heap (a line or page more per
  // element and sweep in a long train).
  static constexpr int kNearPoints = 2;
  std::array<PointRef, kNearPoints> near_points_{};
  std::array<int, kNearPoints> near_point_slot_{};
};

namespace ad {
/// The element state with q seeded as unknowns 0..5 and v as 6..11 of a dual number.
template <class D>
ElementState<D> seeded_state(const ElementState<double>& s) {
  ElementState<D> sd;
  for (int k = 0; k < 2; ++k) {
    const auto ks = static_cast<std::size_t>(k);
    sd.q[ks] = {D(s.q[ks].x, 3 * k), D(s.q[ks].y, 3 * k + 1), D(s.q[ks].theta, 3 * k + 2)};
    sd.v[ks] = {D(s.v[ks].x, 6 + 3 * k), D(s.v[ks].y, 6 + 3 * k + 1), D(s.v[ks].theta, 6 + 3 * k + 2)};
  }
  for (std::size_t k = 0; k < 2; ++k) sd.rotation[k] = rotation_of(sd.q[k].theta, s.rotation[k]);
  sd.mode = s.mode;
  return sd;
}

/// Adds the values of dual forces to f and their q- and v-derivatives to df_dq, df_dv;
/// derivatives with respect to further seeds (12, 13, ...) go to `extra` (rows x extra_count).
template <class D>
void extract_forces(const std::array<Pose<D>, 2>& fd, std::array<Pose<double>, 2>& f, ForceBlock& df_dq, ForceBlock& df_dv,
                    double (*extra)[kMaxConstraintRows] = nullptr, int extra_count = 0) {
  for (int k = 0; k < 2; ++k) {
    const auto ks = static_cast<std::size_t>(k);
    const D* comps[3] = {&fd[ks].x, &fd[ks].y, &fd[ks].theta};
    double* out[3] = {&f[ks].x, &f[ks].y, &f[ks].theta};
    for (int c = 0; c < 3; ++c) {
      *out[c] += comps[c]->value;
      const auto row = static_cast<std::size_t>(3 * k + c);
      for (std::size_t j = 0; j < 6; ++j) {
        df_dq[row][j] += comps[c]->grad[j];
        df_dv[row][j] += comps[c]->grad[6 + j];
      }
      for (int r = 0; r < extra_count; ++r) extra[row][r] += comps[c]->grad[12 + static_cast<std::size_t>(r)];
    }
  }
}
}  // namespace ad

/// Adapter: Derived provides  template <class T> void force_law(double t, const ElementState<T>&, std::array<Pose<T>,2>& f) const
/// which adds its generalized forces to f.
template <class Derived>
class ForceElement : public Element {
 public:
  using Element::Element;

  void add_force(double t, const ElementState<double>& s, std::array<Pose<double>, 2>& f) const override {
    static_cast<const Derived*>(this)->force_law(t, s, f);
  }

  void add_force_jacobian(double t, const ElementState<double>& s, std::array<Pose<double>, 2>& f,
                          ForceBlock& df_dq, ForceBlock& df_dv) const override {
    using D = Dual<double, 12>;
    const ElementState<D> sd = ad::seeded_state<D>(s);
    std::array<Pose<D>, 2> fd{};
    static_cast<const Derived*>(this)->force_law(t, sd, fd);
    ad::extract_forces(fd, f, df_dq, df_dv);
  }
};

/// Adapter: Derived provides  static constexpr int kRows  and
/// template <class T> void constraint_law(const std::array<Pose<T>,2>& q, T* phi) const.
/// A joint with friction also defines
/// template <class T> void joint_force_law(double t, const ElementState<T>&, const T* lambda, std::array<Pose<T>,2>& f) const
/// and returns true from has_joint_force(); AD over (q, v, lambda) gives its derivatives.
template <class Derived>
class ConstraintElement : public Element {
 public:
  using Element::Element;
  int constraint_count() const override { return Derived::kRows; }

  template <class T>
  void joint_force_law(double, const ElementState<T>&, const T*, std::array<Pose<T>, 2>&) const {}

  void add_joint_force(double t, const ElementState<double>& s, const double* lambda,
                       std::array<Pose<double>, 2>& f) const override {
    static_cast<const Derived*>(this)->joint_force_law(t, s, lambda, f);
  }
  /// A joint's reactions do no work on an assembled state; only its friction dissipates.
  bool conservative(const ElementState<double>& /*s*/) const override { return !has_joint_force(); }

  void add_joint_force_jacobian(double t, const ElementState<double>& s, const double* lambda,
                                std::array<Pose<double>, 2>& f, ForceBlock& df_dq, ForceBlock& df_dv,
                                double df_dlambda[6][kMaxConstraintRows]) const override {
    using D = Dual<double, 12 + kMaxConstraintRows>;
    const ElementState<D> sd = ad::seeded_state<D>(s);
    D lambda_d[kMaxConstraintRows];
    for (int r = 0; r < Derived::kRows; ++r) lambda_d[r] = D(lambda[r], 12 + r);
    std::array<Pose<D>, 2> fd{};
    static_cast<const Derived*>(this)->joint_force_law(t, sd, lambda_d, fd);
    ad::extract_forces(fd, f, df_dq, df_dv, df_dlambda, Derived::kRows);
  }

  void constraint(const std::array<Pose<double>, 2>& q, double* phi) const override {
    static_cast<const Derived*>(this)->constraint_law(q, phi);
  }

  void constraint_gradient(const std::array<Pose<double>, 2>& q, double* phi,
                           double gradient[kMaxConstraintRows][6]) const override {
    using D = Dual<double, 6>;
    std::array<Pose<D>, 2> qd;
    for (int k = 0; k < 2; ++k) {
      const auto ks = static_cast<std::size_t>(k);
      qd[ks] = {D(q[ks].x, 3 * k), D(q[ks].y, 3 * k + 1), D(q[ks].theta, 3 * k + 2)};
    }
    D phid[kMaxConstraintRows];
    static_cast<const Derived*>(this)->constraint_law(qd, phid);
    for (int r = 0; r < Derived::kRows; ++r) {
      phi[r] = phid[r].value;
      for (std::size_t j = 0; j < 6; ++j) gradient[r][j] = phid[r].grad[j];
    }
  }

  void constraint_hessian(const std::array<Pose<double>, 2>& q, double* phi, double gradient[kMaxConstraintRows][6],
                          double hessian[kMaxConstraintRows][6][6]) const override {
    using D1 = Dual<double, 6>;
    using D2 = Dual<D1, 6>;
    std::array<Pose<D2>, 2> qd;
    const auto seed = [](double value, int index) { return D2(D1(value, index), index); };
    for (int k = 0; k < 2; ++k) {
      const auto ks = static_cast<std::size_t>(k);
      qd[ks] = {seed(q[ks].x, 3 * k), seed(q[ks].y, 3 * k + 1), seed(q[ks].theta, 3 * k + 2)};
    }
    D2 phid[kMaxConstraintRows];
    static_cast<const Derived*>(this)->constraint_law(qd, phid);
    for (int r = 0; r < Derived::kRows; ++r) {
      phi[r] = phid[r].value.value;
      for (std::size_t i = 0; i < 6; ++i) {
        gradient[r][i] = phid[r].value.grad[i];
        for (std::size_t j = 0; j < 6; ++j) hessian[r][i][j] = phid[r].grad[i].grad[j];
      }
    }
  }
};

/// Local state of element e gathered from the global q and v arrays (ground slots are zero);
/// mode: its slot in the run's ElementStates (DaeSystem::modes()); body_rotation(b, theta)
/// gives a body's Rotation (a cache may serve it).
template <class BodyRotation>
ElementState<double> gather_state(const Element& e, const double* q, const double* v, const void* mode,
                                  BodyRotation&& body_rotation) {
  ElementState<double> s;
  s.mode = mode;
  for (int k = 0; k < 2; ++k) {
    const int b = e.slot_body(k);
    if (b == kGround) continue;
    const auto ks = static_cast<std::size_t>(k);
    s.q[ks] = {q[3 * b], q[3 * b + 1], q[3 * b + 2]};
    s.v[ks] = {v[3 * b], v[3 * b + 1], v[3 * b + 2]};
    s.rotation[ks] = body_rotation(b, q[3 * b + 2]);
  }
  return s;
}
/// The same, each rotation computed afresh.
ElementState<double> gather_state(const Element& e, const double* q, const double* v, const void* mode);
/// The same for an element without modes (mode_bytes() == 0; an internal error otherwise).
ElementState<double> gather_state(const Element& e, const double* q, const double* v);

/// Declares a stateful element's slot: State is its type, start_mode the member holding the
/// mode a run starts in (set by the constructor or initialize()).
#define RAILCRASH_ELEMENT_MODE(State, start_mode)                                         \
  std::size_t mode_bytes() const override { return sizeof(State); }                     \
  void write_start_mode(void* slot) const override { new (slot) State(start_mode); }

}  // namespace railcrash
