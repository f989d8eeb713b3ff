// Consistent initial values for the DAE.
//
// 1. Position assembly: Newton on Phi(q) = 0 from the model's coordinates, taking the
//    smallest weighted correction dq = -W G^T (G W G^T)^-1 Phi, W = diag(1, 1, L^2) per body
//    (L the model's length scale, so angles and lengths weigh alike).
// 2. Velocity projection onto G v = 0 with the same weights.
// Redundant constraints (G without full row rank) and constraints that cannot all hold
// (Newton does not converge) are input errors naming the elements involved.
#pragma once

#include <vector>

#include "railcrash/dae_system.hpp"

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
void consistent_rates(const DaeSystem& system, double t, std::vector<double>& y, std::vector<double>& yp);

/// Throws InputError when the constraint rows are linearly dependent at q, naming them.
void check_constraint_rank(const DaeSystem& system, const double* q);

}  // namespace railcrash
