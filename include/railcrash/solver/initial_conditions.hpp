// Consistent initial values for the DAE.
//
// 1. Position assembly: Newton on Phi(q) = 0 from the model's coordinates, taking the
//    smallest weighted correction dq = -W G^T (G W G^T)^-1 Phi, W = diag(1, 1, L^2) per body
//    (L the model's length scale, so angles and lengths weigh alike).
// 2. Velocity projection onto G v = 0 with the same weights.
// Redundant constraints (G without full row rank) and constraints that cannot all hold
// (Newton does not converge) are input errors naming the elements involved.
#pragma once

#include <memory>
#include <vector>

#include "railcrash/solver/dae_system.hpp"

namespace railcrash {

struct AssemblyReport {
  double largest_position_change = 0.0;  // [length] (angles times the length scale)
  double largest_velocity_change = 0.0;  // [length/time]
  int newton_iterations = 0;
};

/// Makes y (from DaeSystem::initial_state) satisfy Phi(q) = 0 and G v = 0.
AssemblyReport assemble_initial_state(const DaeSystem& system, std::vector<double>& y);

/// Consistent rates for a y with Phi = 0 and G v = 0: q' = v, mu = 0, and (v', lambda) from
///   [ M  G^T ] [ v'     ]   [ f(t, q, v) ]
///   [ G  0   ] [ lambda ] = [ -gamma     ]   (the hidden acceleration constraint).
/// IDACalcIC cannot do this for the GGL form: there the algebraic equations Phi = 0 and
/// G v = 0 do not involve the algebraic unknowns, so lambda is fixed only by this hidden
/// constraint. Throws SolverError when the matrix is singular (a body with zero inertia
/// that no joint holds).
///
/// With a `cache`, the fill-reducing ordering of the matrix (a function of its pattern only) is
/// kept and reused while the pattern stays the same, as it does between most restarts of a
/// run: the factors, and so the rates, are the same bit for bit as without one.
class ConsistentRatesCache;
void consistent_rates(const DaeSystem& system, double t, std::vector<double>& y, std::vector<double>& yp,
                      ConsistentRatesCache* cache = nullptr);

/// What consistent_rates keeps from one call to the next for one model: the sparse LU object
/// with its ordering and work storage, and the pattern the ordering was made for.
class ConsistentRatesCache {
 public:
  ConsistentRatesCache();
  ~ConsistentRatesCache();
  ConsistentRatesCache(const ConsistentRatesCache&) = delete;
  ConsistentRatesCache& operator=(const ConsistentRatesCache&) = delete;
  /// Calls that reused the ordering, and calls that made one (statistics for tests and benchmarks).
  long reused() const;
  long analysed() const;

 private:
  friend void consistent_rates(const DaeSystem&, double, std::vector<double>&, std::vector<double>&, ConsistentRatesCache*);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct EquilibriumReport {
  int steps = 0;                         // pseudo-time steps taken
  double largest_position_change = 0.0;  // [length] (angles times the length scale)
  double residual_force = 0.0;           // [force] largest unbalanced generalized force left
};

/// Static equilibrium under gravity and the loads at t = 0: moves the bodies of y (from
/// DaeSystem::initial_state, joints assembled) until forces and joint reactions balance,
/// with every element's mode kept consistent (contacts close, springs pass breakpoints);
/// committed mode changes are appended to `events`. Velocities in y are kept, and ignored
/// while settling (a static state has none).
///
/// Pseudo-transient continuation: each step solves
///   [ M / h^2 + K   G^T ] [ dq ]     [ f(q) - G^T lambda ]
///   [ G             0   ] [ dl ] = - [ Phi(q)            ]   (signs as in the DAE residual)
/// with K = -df/dq + d(G^T lambda)/dq from the DAE Jacobian, in the modes of the current
/// state; h grows after an accepted step (toward Newton) and shrinks after a rejected one.
/// M / h^2 keeps free directions (a car on its rails) regular. Each step is limited to a
/// trust region (0.05 % of the model size, 0.01 rad: the settle follows the state down as a
/// heavily damped motion would); the trial state is projected onto the joints and every
/// element is put in the mode of the trial state (all roots that turned negative are
/// committed, repeatedly) before the step is judged.
/// Acceptance (why the settle does not stall on kinks): a step is accepted when the
/// unbalanced forces do positive work along it (trapezoidal rule of the residual forces at
/// both ends), i.e. when it goes down the model's energy. The energy of piecewise-linear
/// laws is continuously differentiable across their kinks where the force residual is not,
/// so a Newton step that jumps over a kink into a stiff segment meets a large opposing force
/// at its end and is shortened, and a state whose equilibrium lies on (or next to) a kink is
/// approached from either side without the residual norm having to fall monotonically (the
/// criterion of the earlier version, which stalled there). When the work is at round-off,
/// the residual norm must fall instead (Newton's last, quadratic steps). The work of the
/// residual needs no energy function, so non-conservative laws (hysteresis, plasticity)
/// take part as they stand. A rejected step puts the elements back in the modes of the
/// current state (a snapshot restored through a ModeTracker, the modes' one writer); a
/// history change (yield, fracture) committed at a rejected trial state stays, unlogged (none
/// in the report's models).
/// A model with several equilibria reaches the one this damped descent leads to.
/// Throws SolverError when it does not settle.
EquilibriumReport settle_static_equilibrium(DaeSystem& system, std::vector<double>& y,
                                            std::vector<EventRecord>& events);

struct StartReport {
  AssemblyReport assembly;
  EquilibriumReport equilibrium;
};

/// The state a run starts from: every element in its starting mode (ModeTracker::reset_modes),
/// the model's coordinates with the joints assembled, then (static_equilibrium: the run's
/// simulation.static_equilibrium) settled under gravity with the model's velocities projected
/// onto the joints.
StartReport prepare_start(DaeSystem& system, std::vector<double>& y, std::vector<EventRecord>& events, bool static_equilibrium);

/// Throws InputError when the constraint rows are linearly dependent at q, naming them.
void check_constraint_rank(const DaeSystem& system, const double* q);

/// Constraint rows in a linearly dependent set at q (a column-pivoted sparse QR of G^T with the
/// given pivot threshold); rank receives G's rank. Empty when G has full rank.
/// How the rows of G are scaled before the rank-revealing QR: AssemblyWeights, G W^1/2 (the
/// assembly's metric, for exact redundancy at a threshold near round-off); UnitRows, angles as
/// arcs at each body's size (DaeSystem::body_angle_lengths) and every row of unit length, so
/// that the threshold is the share of a row outside the others' span (near-singularity).
enum class RowScaling { AssemblyWeights, UnitRows };
std::vector<int> dependent_constraint_rows(const DaeSystem& system, const double* q, double pivot_threshold, int& rank,
                                           RowScaling scaling = RowScaling::AssemblyWeights);

/// After a solver failure: "singular configuration: joints 'a' (pin_joint, line 9), ... lose
/// rank at t = ..." when G at q is nearly rank deficient; a note when the model is too large
/// to check (more than 2000 constraint rows); "" otherwise.
std::string singular_configuration(const DaeSystem& system, const double* q, double t);

}  // namespace railcrash
