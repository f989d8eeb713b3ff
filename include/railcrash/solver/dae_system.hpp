// The DAE the integrators see (they never see an element).
//
// Stabilized index-2 (Gear-Gupta-Leimkuhler) form, unknowns y = [q, v, lambda, mu]:
//   r_q   = q' - v + G^T mu          (3n, differential)
//   r_v   = M v' - f(t, q, v) + G^T lambda   (3n, differential)
//   r_phi = Phi(q)                    (m, algebraic)
//   r_vel = G v                       (m, algebraic)
// Jacobian J = dr/dy + cj dr/dy' in compressed sparse columns. Its pattern is learned once
// by a dry run of the same assembly code against a recorder; every later evaluation
// replays the same sequence of additions into precomputed value slots. Rows of a failed
// constraint (later: lambda = 0, mu = 0) already have their diagonal slots, so the pattern
// never changes.
//
// The same element code also gives the plain generalized forces for explicit integration,
// with constraints replaced by penalty spring-dampers.
//
// A DaeSystem is one run's view of an immutable Model and a const evaluator of it: every public
// method that evaluates (residual, Jacobian, forces, roots, outputs, energy) is const, reads the
// run's element modes and histories (ElementStates, modes()) and changes nothing, and no public
// member changes the modes. The storage of the modes sits beside the evaluator (one per system,
// so the settle's, the integrator's and a test's trackers of one system share it and it lives as
// long as the system), but it is written only by the mode-tracking side (events.hpp:
// ModeTracker, a friend): its commits, its reset to the start modes and its snapshot restore.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "railcrash/model/model.hpp"

namespace railcrash {

/// Compressed sparse column structure of the Jacobian.
struct SparsePattern {
  int size = 0;
  std::vector<int> column_start;  // size + 1
  std::vector<int> row_index;     // nonzeros
  int nonzeros() const { return static_cast<int>(row_index.size()); }
};

/// One committed mode change, for events.csv.
struct EventRecord {
  double t = 0.0;
  std::string element;
  std::string what;
  double value = 0.0;
  bool kink = false;  // the element's force is continuous across it (Element::EventKind::Kink)
};

/// Penalty stiffness and damping per constraint row (explicit Euler).
struct PenaltyRows {
  std::vector<double> stiffness;  // [force/length] or [moment/rad]
  std::vector<double> damping;    // [force*time/length] or [moment*time/rad]
};

/// Energy figures of one state [force*length]; work terms are the quadratures so far.
struct EnergyState {
  double kinetic = 0.0;
  double elastic = 0.0;       // stored in elements (and penalty springs)
  double gravity = 0.0;       // potential of gravity, -sum m g . r
  double element_work = 0.0;  // work done on elements (and penalties) by the bodies
  double load_work = 0.0;     // work done by applied loads
  // Per element: stored energy, work done on it (its quadrature), and whether it can dissipate
  // in the state's mode (not Element::conservative); then the same for Euler's penalty joints.
  std::vector<double> element_elastic, element_work_done;
  std::vector<char> element_dissipates;
  double penalty_elastic = 0.0, penalty_work = 0.0;
};

/// Energy balance between a start state and now [force*length].
/// dissipated sums, over the elements that can dissipate (Element::conservative false at
/// `now`) and Euler's penalty joints, the work done on them less the change of their stored
/// energy; a conservative element dissipates nothing by construction. What the balance then
/// leaves over is the integration's error, not any element's: integration_drift().
struct EnergyBalance {
  double kinetic = 0.0;
  double elastic = 0.0;       // stored in elements (and penalty springs)
  double gravity = 0.0;       // potential of gravity, zero at the initial configuration
  double dissipated = 0.0;    // by elements (and penalty dampers)
  double external_work = 0.0; // done by applied loads
  double initial_total = 0.0;
  /// Energy the integration lost: initial_total + external_work - (kinetic + elastic + gravity
  /// + dissipated) [force*length]; zero for an exact solution, positive when the numerical
  /// solution lost energy. For a model of conservative elements, initial - final total energy.
  double integration_drift() const { return initial_total + external_work - (kinetic + elastic + gravity + dissipated); }
  /// The same with the opposite sign (energy gained), as summary.json's balance_error.
  double error() const { return -integration_drift(); }
  /// The energy turned over, the scale the drift is judged against (the accuracy warnings,
  /// integrator auto): max(|initial total|, |kinetic| + |elastic| + |gravity| + |dissipated|
  /// + |external work|) [force*length].
  double turned_over() const {
    return std::max(std::abs(initial_total),
                    std::abs(kinetic) + std::abs(elastic) + std::abs(gravity) + std::abs(dissipated) + std::abs(external_work));
  }
  static EnergyBalance between(const EnergyState& start, const EnergyState& now);
};

class DaeSystem {
 public:
  explicit DaeSystem(const Model& model);

  const Model& model() const { return model_; }
  int size() const { return model_.size(); }
  int body_unknowns() const { return 3 * model_.body_count(); }
  int constraint_rows() const { return model_.constraint_rows(); }

  /// y at t = 0 from the model's bodies (lambda = mu = 0).
  std::vector<double> initial_state() const;
  /// 1 for differential unknowns (q, v), 0 for algebraic ones (lambda, mu).
  std::vector<double> differential_ids() const;

  void residual(double t, const double* y, const double* yp, double* r) const;
  const SparsePattern& pattern() const { return pattern_; }
  /// Writes the Jacobian values in pattern order (values has pattern().nonzeros() entries).
  void jacobian(double t, double cj, const double* y, const double* yp, double* values) const;
  /// values += factor dr/dy' in pattern order: the rates' part of the Jacobian, the identity on
  /// the position rows and the mass matrix on the velocity rows (nothing else reads y'). With
  /// factor = cj_new - cj_old it turns jacobian(t, cj_old, ...) into jacobian(t, cj_new, ...).
  void add_rate_jacobian(double factor, double* values) const;

  /// Generalized forces f(t, q, v) from gravity, loads and force elements; when penalty is
  /// given, constraints add -G^T (k Phi + c G v) and penalty_lambda receives k Phi + c G v.
  /// Joint friction needs the reactions: the penalty forces, or else `lambda` (the DAE's
  /// multipliers; without either, joint friction is left out).
  /// `extras` asks the same sweep over the elements for more (explicit Euler's one sweep per
  /// step instead of four).
  struct SweepExtras {
    double* powers = nullptr;   // quadrature_count(): what quadrature_rates(t, y, powers, penalty_lambda) gives
    double* roots = nullptr;    // root_count(): what roots(t, y, roots) gives for y = (q, v, y_lambda)
    double* outputs = nullptr;  // output_names().size(): what outputs(y, y_lambda, outputs) gives
    const double* y_lambda = nullptr;  // the multipliers in y that the roots and outputs read
    /// With `outputs`: per element, nonzero when its outputs are wanted (the others' places in
    /// `outputs` are left as they were); null: every element's.
    const char* output_elements = nullptr;
  };
  void generalized_forces(double t, const double* q, const double* v, double* f, const PenaltyRows* penalty = nullptr,
                          double* penalty_lambda = nullptr, const double* lambda = nullptr,
                          const SweepExtras* extras = nullptr) const;
  /// generalized_forces(t, q, v, f, nullptr, nullptr, lambda) for a run of calls at one t, q
  /// and v in which only lambda changes (consistent_rates' iteration on the joints' friction).
  /// The first call (`fixed.ready` false) keeps gravity and the loads, and each element's forces
  /// that do not depend on lambda, in `fixed`; every call then evaluates only the joints'
  /// friction and adds the elements' forces in generalized_forces' order, so f is the same bit
  /// for bit as generalized_forces'.
  struct ForcesAtReactions {
    bool ready = false;
    std::vector<double> base;                            // gravity and loads, per body unknown
    std::vector<std::array<Pose<double>, 2>> elements;   // each element's forces without friction
  };
  void generalized_forces_at_reactions(double t, const double* q, const double* v, const double* lambda, double* f,
                                       ForcesAtReactions& fixed) const;
  /// Triplets of df/dq and df/dv (same force definition as generalized_forces); with
  /// `stiffest`, each element in its stiffest mode (Euler's stability estimate).
  struct Triplet { int row, col; double value; };
  void force_jacobian(double t, const double* q, const double* v, const PenaltyRows* penalty,
                      std::vector<Triplet>& df_dq, std::vector<Triplet>& df_dv, bool stiffest = false) const;

  /// Phi(q) and G = dPhi/dq (triplets, row = constraint row, col = q index).
  void constraints(const double* q, double* phi, std::vector<Triplet>* gradient) const;
  /// gamma_r = v^T (d^2 Phi_r / dq^2) v, so that the acceleration constraint is G v' + gamma = 0.
  void constraint_acceleration_bias(const double* q, const double* v, double* gamma) const;
  /// Largest |Phi| over rows (lengths and angles*length_scale mixed: a quality figure).
  double constraint_residual(const double* q) const;
  /// The same with phi as work space (no allocation per call: the run's every output sample).
  double constraint_residual(const double* q, std::vector<double>& phi) const;
  /// Element owning constraint row `row`.
  const Element& constraint_owner(int row) const;
  /// Index of the element owning constraint row `row`.
  int constraint_row_owner(int row) const { return constraint_row_owner_[static_cast<std::size_t>(row)]; }

  // ---- what integrators ask about the elements, without reading them ----
  int element_count() const { return static_cast<int>(model_.elements().size()); }
  /// Element e in messages: "model.yaml:20: element 'pin' (revolute)" (`noun` for "element").
  std::string element_label(int e, const char* noun = "element") const;
  /// True once element e, an element with constraint rows, has failed: its equations changed
  /// (lambda = mu = 0), so an integrator cannot go on across the change.
  bool constraint_element_failed(int e) const;
  /// The length over which each body's angle counts, for angular tolerances: an angle error
  /// d_theta moves the body's points by r d_theta. r is the larger of the body's radius of
  /// gyration and its farthest connection point, kept within [1e-3, 1] x the model's length
  /// scale; a point mass without connections gets the length scale. One entry per body.
  std::vector<double> body_angle_lengths() const;
  /// What constraint row `row`'s residual counts as in length units [length per residual
  /// unit]: 1 for a distance row; for an angle row the larger of its two bodies' sizes (radius
  /// of gyration or farthest connection point, as body_angle_lengths without its bounds), the
  /// distance by which an angle misfit moves the farther points. Where the model sits and how
  /// long the train is do not enter (an angle row used to count times the model's length
  /// scale, which grows with the distance from the origin: bench/HISTORY.md, "Joint openings
  /// at the bodies' own size"). A row between bodies without size gets the model's
  /// origin-free length.
  double constraint_row_length(int row) const { return row_length_[static_cast<std::size_t>(row)]; }
  /// Per constraint row, an upper bound of 1 / (its effective mass) over all orientations of
  /// its bodies: a translational row moves body b's point at distance a_b from its centre, so
  /// 1 / m_eff <= sum 1/m_b + a_b^2/J_b; an angle row gives sum 1/J_b [1/mass] or [1/inertia].
  std::vector<double> constraint_row_inverse_mass_bounds() const;
  /// The penalty keys of the element owning constraint row `row` (explicit Euler's penalties).
  const Element::PenaltyOverrides& constraint_row_penalty(int row) const { return constraint_owner(row).penalty(); }
  /// Unknown k of y in the model's terms, with file:line: "model.yaml:7: body 'cab' vx",
  /// "model.yaml:20: element 'pin' (revolute) multiplier of its constraint row 1".
  std::string unknown_name(int k) const;
  /// Where a non-finite value at (t, y, y') comes from, in the model's terms with file:line:
  /// a non-finite unknown or rate, else the first element whose forces, constraint equations,
  /// gradients or Jacobian entries are not finite (each element evaluated alone), else the mass
  /// matrix or a load, else the residual row that overflows; "" when everything is finite.
  std::string non_finite_source(double t, const double* y, const double* yp) const;
  /// False once the element owning constraint row `row` has failed (its rows: lambda = mu = 0).
  bool constraint_row_active(int row) const {
    return !element_failed(static_cast<std::size_t>(constraint_row_owner_[static_cast<std::size_t>(row)]));
  }
  /// True once element e has failed (a failed constraint: lambda = mu = 0).
  bool element_failed(std::size_t e) const;
  /// True when constraint row `row` is an angle equation.
  bool constraint_row_is_rotational(int row) const { return row_is_rotational_[static_cast<std::size_t>(row)]; }

  // ---- quadratures integrated alongside: [ integral of kinetic energy dt,
  //      work of applied loads, work done on each element (by the bodies), work on penalties ]
  int quadrature_count() const { return 3 + static_cast<int>(model_.elements().size()); }
  /// With `g` (root_count()) and `outputs` (output_names().size()), y holding the multipliers
  /// as IDA's does, the root functions and the element outputs at (t, y) as well, from the same
  /// sweep, equal bit for bit to roots(t, y, g, outputs): IDA evaluates the quadratures at the
  /// corrected state of each step it tries, so the accepted step's roots and outputs need no
  /// sweep of their own.
  void quadrature_rates(double t, const double* y, double* rates, const double* penalty_lambda = nullptr,
                        double* g = nullptr, double* outputs = nullptr) const;
  /// The rates that do not come from elements (kinetic energy, loads' power); the rest is
  /// written by quadrature_rates or by generalized_forces' `powers`.
  void body_quadrature_rates(double t, const double* q, const double* v, double* rates) const;
  static constexpr int kKineticIntegral = 0;
  static constexpr int kLoadWork = 1;
  static constexpr int kPenaltyWork = 2;
  static constexpr int kFirstElementWork = 3;

  double kinetic_energy(const double* v) const;
  /// Potential of gravity, -sum m g . r [force*length].
  double gravity_potential(const double* q) const;
  EnergyState energy(const double* y, const double* quadratures, const PenaltyRows* penalty = nullptr) const;
  /// The run's energy theorem since `start` with every element's stored and dissipated energy
  /// taken as the work done on it (its quadrature), at state (y, quadratures): K + V_gravity +
  /// sum W - W_loads keeps its start value on the exact solution. From the quadratures alone
  /// (no element evaluated), so cheap enough for every step or sample. [force*length]
  struct WorkBalance {
    double lost = 0.0;         // the energy the integration lost (< 0: created)
    double turned_over = 0.0;  // max(|initial kinetic + elastic|, kinetic + |change of gravity|
                               //     + |work done on the elements and penalties| + |work of the loads|)
  };
  /// Its turned_over's largest value over a run is the scale of the run's energy error
  /// (RunOutcome::most_energy_turned_over): at one instant every energy can be near zero (a
  /// pendulum from rest back at its turning point).
  WorkBalance work_balance(const EnergyState& start, const double* y, const double* quadratures) const;
  /// Element e's stored elastic energy at the state y [force*length], its bodies' rotations from
  /// the same cache as every sweep (an output row has computed them already).
  double element_potential_energy(std::size_t e, const double* y) const;
  /// The same and whether the element can dissipate in its current mode (not
  /// Element::conservative), from one local state.
  struct StoredEnergy {
    double stored = 0.0;      // [force*length]
    bool dissipates = true;
  };
  StoredEnergy element_stored_energy(std::size_t e, const double* y) const;

  // ---- modes and events ----
  int root_count() const { return root_count_; }
  /// How many root functions element e has (its roots are root_offset(e) onwards).
  int element_root_count(int e) const {
    const auto next = static_cast<std::size_t>(e) + 1;
    return (next < root_offset_.size() ? root_offset_[next] : root_count_) - root_offset_[static_cast<std::size_t>(e)];
  }
  /// All elements' root functions at y, in element order. With `outputs`
  /// (output_names().size()), every element's outputs at y as well, from the same evaluation of
  /// its local state (IDA's one sweep after a step; outputs(y, y's multipliers) gives the same).
  void roots(double t, const double* y, double* g, double* outputs = nullptr) const;
  /// Element-level access for integrators that locate events element by element.
  int root_offset(int e) const { return root_offset_[static_cast<std::size_t>(e)]; }
  /// Element owning root k.
  int root_owner(int k) const { return root_owner_[static_cast<std::size_t>(k)]; }
  /// Element e's root functions at y (only its bodies' q, v and its multipliers are read).
  void element_roots(int e, double t, const double* y, double* g) const;
  /// The unknowns element e reads: its bodies' positions and velocities and its multipliers.
  const std::vector<int>& element_unknowns(int e) const { return element_unknowns_[static_cast<std::size_t>(e)]; }
  /// Element e's local state at y (its bodies' poses and velocities, its mode) and its
  /// multipliers in y (null when it has no constraint rows): what its commit reads.
  ElementState<double> element_state(int e, const double* y) const {
    return local_state(static_cast<std::size_t>(e), y, y + body_unknowns());
  }
  const double* element_multipliers(int e, const double* y) const;
  /// What element e alone contributes at y: its generalized forces on its two body slots (force
  /// elements, and joint friction from the multipliers in y; not the constraint rows) and the
  /// power delivered to it (its work quadrature's rate). Lets an integrator judge a mode change
  /// from the elements that changed instead of the whole model.
  struct ElementLoad {
    std::array<int, 2> body{kGround, kGround};  // slot bodies (kGround: none)
    std::array<Pose<double>, 2> force{};        // [force], [force*length]
    double power = 0.0;                         // [force*length/time]
  };
  ElementLoad element_load(int e, double t, const double* y) const;
  /// At a (re)start at (t, y, y'): the roots that sit on their mode's boundary and are about to
  /// leave it, judged by a second-order look-ahead of h = 1e-6 min(1, t_end) along y' (t_end:
  /// the run's end in its settings [time]; roots that fire within h are taken as simultaneous
  /// with the restart), and roots already
  /// negative (the state is outside its mode, e.g. after the initial assembly moved it):
  /// direction[k] = -1 for each (root_count() entries), else 0; true when any. Elements switch
  /// a small band past their boundaries (1e-14 to 1e-12 of their size), so a state exactly on a
  /// boundary has a small positive root that the look-ahead sees cross; IDA itself would leave
  /// a root that is exactly zero inactive. ModeTracker::commit_boundary commits them.
  bool boundary_roots_leaving(double t, const double* y, const double* yp, double t_end, std::vector<int>& direction) const;
  /// The run's element modes and histories, as the evaluations read them. Only a ModeTracker
  /// (events.hpp) changes them: its commits, reset_modes(), restore().
  const ElementStates& modes() const { return modes_; }

  /// Element output columns "<element>.<quantity>" and their values at y.
  const std::vector<std::string>& output_names() const { return output_names_; }
  void outputs(const double* y, const double* lambda, double* out) const;
  /// Element e's outputs only, into their places in the whole array `out` (as outputs() fills it).
  void element_outputs(int e, const double* y, const double* lambda, double* out) const;
  /// How many times element e's outputs have been evaluated by this system (outputs(),
  /// element_outputs(), and the sweeps that fill outputs): what an integrator's per-step
  /// output work costs, for the tests.
  long output_evaluations(int e) const { return output_evaluations_[static_cast<std::size_t>(e)]; }
  /// Element e's columns of outputs(): first, one past the last.
  std::pair<int, int> output_range(int e) const {
    return {output_offset_[static_cast<std::size_t>(e)], output_end(static_cast<std::size_t>(e))};
  }

  /// Mass-matrix diagonal entry of body unknown k (mass or inertia).
  double mass_diagonal(int k) const { return mass_[static_cast<std::size_t>(k)]; }

 private:
  template <class Sink>
  void assemble_jacobian(double t, double cj, const double* y, const double* yp, Sink& sink) const;
  /// Element e's local state at (q, v), with its mode; its slots' rotations come from
  /// body_rotation().
  ElementState<double> local_state(std::size_t e, const double* q, const double* v) const;
  /// cos and sin of body b's angle theta [rad], computed once per distinct angle: every
  /// element on the body, and every sweep at the same state (Euler's forces, powers, roots and
  /// outputs), reuse them. A cache keyed by the angle's value, so it is never stale.
  const Rotation<double>& body_rotation(int b, double theta) const;
  void load_forces(double t, const double* q, double* f) const;
  /// f = gravity on every body, plus the loads: where the generalized forces start.
  void gravity_and_load_forces(double t, const double* q, double* f) const;
  /// One past element e's last output in output_names().
  int output_end(std::size_t e) const;
  /// Element e's roots into g and its outputs into `outputs` (their places in the whole arrays;
  /// either may be null) at its local state s; lambda: all the multipliers (y + 2 nq). With the
  /// next one, the places roots(), the quadratures' sweep and generalized_forces' extras
  /// evaluate them.
  void element_roots_and_outputs(std::size_t e, double t, const ElementState<double>& s, const double* lambda, double* g,
                                 double* outputs) const;
  /// The same and force element e's force f (added to), from one evaluation where the element
  /// shares it (Element::force_roots_and_outputs): the step sweeps'.
  void element_force_roots_and_outputs(std::size_t e, double t, const ElementState<double>& s, const double* lambda,
                                       std::array<Pose<double>, 2>& f, double* g, double* outputs) const;
  /// Element e's multipliers, roots and outputs within the whole arrays (null where it has none
  /// or the array is null).
  struct ElementSlices {
    const double* lambda = nullptr;
    double* g = nullptr;
    double* outputs = nullptr;
  };
  ElementSlices element_slices(std::size_t e, const double* lambda, double* g, double* outputs) const;

  friend class ModeTracker;  // the only writer of modes_

  const Model& model_;
  ElementStates modes_;  // the run's element modes and histories: read here, written only by ModeTracker
  std::vector<double> mass_;  // 3n diagonal of M
  SparsePattern pattern_;
  std::vector<int> slots_;    // value slot of every addition, in assembly order
  std::vector<std::string> output_names_;
  std::vector<int> output_offset_;  // first output of each element in output_names_
  std::vector<int> constraint_row_owner_;  // element index of each constraint row
  std::vector<bool> row_is_rotational_;
  std::vector<double> row_length_;  // constraint_row_length, per row [length per residual unit]
  std::vector<int> root_offset_;  // first root of each element
  std::vector<int> root_owner_;   // element of each root
  std::vector<std::vector<int>> element_unknowns_;  // y indices each element reads
  int root_count_ = 0;
  // body_rotation()'s cache: the angle [rad] each rotation was computed for (NaN: none yet).
  // Mutable scratch of const evaluations; a DaeSystem belongs to one run on one thread.
  mutable std::vector<double> rotation_angle_;
  mutable std::vector<Rotation<double>> rotation_;
  mutable std::vector<long> output_evaluations_;  // per element: output_evaluations()
};

}  // namespace railcrash
