// Helpers shared by the unit tests.
#pragma once

#include <random>
#include <string>
#include <vector>

#include "railcrash/dae_system.hpp"
#include "railcrash/integrator.hpp"
#include "railcrash/model.hpp"

namespace railcrash::testing {

/// Loads a model from YAML text (file name "test.yaml" in messages).
Model model_from_text(const std::string& yaml);

/// Largest relative difference between the assembled Jacobian dF/dy + cj dF/dy' and a
/// central finite difference of the residual, at the given y, yp, beyond the difference
/// quotient's round-off floor (100 eps |r| / h for residual entries of size |r|). Also checks that every
/// nonzero of the finite-difference Jacobian lies inside the sparsity pattern
/// (outside_pattern receives the largest |entry| found outside it).
double jacobian_error(const DaeSystem& system, double t, double cj, const std::vector<double>& y,
                      const std::vector<double>& yp, double* outside_pattern = nullptr);

/// Runs the model with the integrator its settings ask for (no files, output every
/// output_interval) and requires success.
RunOutcome simulate(const Model& model, double output_interval = 0.01);

/// The R1 test model (SI): a 1000 kg car end at 2 m/s into an anticlimber fixed to ground
/// (elastic to 0.01 m at 1e7 N/m, then 1e5 N/m), with a responses section (reference crush
/// 0.02 m), simulated to t_end.
std::string anticlimber_r1_model_text(double t_end);

/// Positions and velocities of a DAE state.
struct BodyState {
  std::vector<double> q, v;
};
BodyState split(const DaeSystem& system, const std::vector<double>& y);
/// Generalized forces (gravity, loads, force elements) at that state, t = 0.
std::vector<double> forces(const DaeSystem& system, const BodyState& s);

/// A random state near the model's initial one (positions, velocities, multipliers).
std::vector<double> random_state(const DaeSystem& system, std::mt19937& rng, double spread = 0.3);

}  // namespace railcrash::testing
