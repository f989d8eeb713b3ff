// What both integrators share: run statistics, the observer that receives output samples,
// and the outcome of a run. Integrators see a DaeSystem, never an element.
#pragma once

#include <atomic>
#include <string>
#include <vector>

#include "railcrash/dae_system.hpp"

namespace railcrash {

struct RunStatistics {
  long steps = 0;
  long residual_evaluations = 0;   // ida: residual calls; euler: force evaluations
  long jacobian_evaluations = 0;
  long nonlinear_iterations = 0;
  long error_test_failures = 0;
  long nonlinear_convergence_failures = 0;
  long events = 0;
  long root_returns = 0;       // ida: mode changes located within a step (summary: located_mode_changes)
  long reinitializations = 0;  // ida: restarts (a mode change the step could not absorb); euler: mode changes
  double wall_seconds = 0.0;
  double last_step = 0.0;          // [time]
  double stability_limit = 0.0;    // euler: [time] estimated largest stable step
  double assembly_correction = 0.0;  // [length] largest move of the initial position assembly
  long settling_steps = 0;           // static equilibrium: pseudo-time steps
  double settling_displacement = 0.0;  // [length] static equilibrium: largest move
};

/// Receives the state at every output time (t = 0 included).
class RunObserver {
 public:
  virtual ~RunObserver() = default;
  /// lambda: constraint multipliers (ida) or penalty forces (euler); quadratures as in DaeSystem.
  virtual void sample(double t, const double* y, const double* lambda, const double* quadratures) = 0;
  /// A committed mode change (contact, yield, rupture, ...); y is the state at that instant.
  virtual void event(const EventRecord& /*record*/, const double* /*y*/) {}
};

struct RunOutcome {
  bool ok = false;
  std::string message;
  double t_reached = 0.0;
  RunStatistics stats;
  std::vector<double> y;            // final state
  std::vector<double> quadratures;  // final quadratures
  EnergyState initial_energy;
  EnergyState final_energy;
  double max_constraint_residual = 0.0;  // largest |Phi| over the output samples [length]
  std::vector<EventRecord> events;       // every committed mode change, in order
};

class Integrator {
 public:
  virtual ~Integrator() = default;
  virtual const char* name() const = 0;
  /// Integrates from 0 to t_end, sampling every output_interval; stops early (ok = false,
  /// message says why) on failure or when *stop becomes true.
  virtual RunOutcome run(double t_end, double output_interval, RunObserver& observer,
                         const std::atomic<bool>* stop = nullptr) = 0;
};

/// Largest |Phi| tracker shared by the integrators.
double max_abs(const std::vector<double>& values);

}  // namespace railcrash
