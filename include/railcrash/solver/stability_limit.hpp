// The largest step explicit Euler (velocity first: v += dt M^-1 f; q += dt v) stays stable
// with on a model, from the model's stiffest and most damped modes at a state. For a mode
// with circular frequency w and damping rate c (= 2 zeta w) the scheme is stable for
//   dt < 2 / (sqrt(w^2 + (c/2)^2) + c/2).
// The largest w and c come from the eigenvalues of M^-1/2 K M^-1/2 and M^-1/2 C M^-1/2
// (K = -df/dq, C = -df/dv in the elements' stiffest modes, penalty rows included when given):
// exactly for models up to 600 unknowns, otherwise bounded above by Gershgorin's theorem (a
// safe, possibly pessimistic limit). 2 / w is also the model's shortest time scale: Euler
// picks its step from it, IDA its absolute position tolerance (README "Position tolerances"),
// `railcrash check` prints it and `converge` plans its steps from it. A property of the
// DaeSystem, not of an integrator.
#pragma once

#include <vector>

#include "railcrash/solver/dae_system.hpp"

namespace railcrash {

/// Largest stable explicit Euler step [time] at state y (q, v, ...), with Euler's penalty rows
/// for the constraints or without them (nullptr: the elements alone); infinity for a model
/// without stiffness or damping.
double explicit_stability_limit(const DaeSystem& system, const std::vector<double>& y, const PenaltyRows* penalty);

}  // namespace railcrash
