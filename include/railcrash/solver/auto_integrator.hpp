// integrator: auto (the default when a model names none): IDA, handing the rest of the run to
// explicit Euler where Euler is clearly the cheaper and resolves the motion at least as finely
// as IDA's error control asks (as LSODA switches between its methods from the step sizes).
//
// The rule, deterministic (counts, never clock readings: a run chooses the same on any machine
// and under any load, so a study's runs differ only by their inputs):
// * Euler's step dt_E is the one a plain Euler run of the model would take (the model's dt, or
//   half the stability limit at the start; EulerIntegrator::choose_step). Where Euler cannot
//   run the model (a body without inertia, a dt above the stability limit, more steps than
//   --max-steps), IDA keeps the run and the reason says why.
// * Cost in force sweeps (one evaluation of every element's force law), from the phase
//   timings of the benchmark models (bench/HISTORY.md, "integrator: auto"): an Euler step 1.1;
//   an IDA step 6 (its Newton residuals and solves, a share of the Jacobians and
//   factorizations, the step's sweep of roots and outputs; 6-11 measured, the lowest taken so
//   that the rule errs towards keeping IDA); an IDA restart 10 more.
// * After IDA's first startup_steps steps (its start from a tiny step is no measure of its
//   pace), IDA's cost since then is compared after every step with Euler's over the same
//   span, 1.1 (t - t_w) / dt_E. IDA hands the run over when, over a span of at least
//   min_span_steps Euler steps and after at least min_events mode changes,
//     (1) its cost exceeds Euler's by the margin (1.5),
//     (2) its mean step over the span is at least dt_E: Euler, first order, is not to take
//         coarser steps than IDA's error control needs. On the SI multiple-unit examples
//         IDA's mean step is a third to a seventh of Euler's stable step, and Euler there is
//         up to 16 % off in a trailing car's crush and 7-16 % in the energy the crush zones
//         absorb (bench/HISTORY.md, "integrator: auto"): cheaper, but not at the same
//         accuracy, so IDA keeps those runs; and
//     (3) Euler's penalty joints, carrying the loads IDA's multipliers say the joints carry,
//         would stand open by less than the trial's limit below (|lambda| / k per row): on
//         EN 15227's scenario 2 built from emu3_wall the first Euler step opened a joint by
//         9 mm, sampled before the trial could give the run back.
// * Euler goes on from IDA's state at the end of that step, in the element modes reached.
// * Euler is on trial: at each output sample, and every 50 of its steps between samples far
//   apart, it measures what the accuracy warnings measure (results/accuracy_check.hpp), its
//   own energy drift since the hand-over as a share of the
//   energy turned over, and how far its penalty joints open. Past half of either warning's
//   limit (0.5 % of the energy, 0.5 mm), IDA takes the run back from Euler's state (the joints
//   closed, consistent rates, a restart with IDA's objects of before) and keeps it. A rule
//   from step sizes cannot see that Euler, first order, drifts where IDA at the same mean
//   step does not: on emu3_wall (IDA's mean step 0.1197 ms, Euler's 0.1186 ms) Euler alone
//   ends 15.7 % off in a car's crush with 10 % of the energy created (bench/HISTORY.md,
//   "Euler on trial").
// The run's output and summary.json ("integrator_used") say which method ran when and why.
#pragma once

#include <optional>
#include <string>

#include "railcrash/solver/euler_integrator.hpp"
#include "railcrash/solver/ida_integrator.hpp"

namespace railcrash {

struct AutoSettings {
  long startup_steps = 20;        // IDA steps before its pace is measured
  long min_events = 5;            // mode changes before a hand-over
  double min_span_steps = 10.0;   // [Euler steps] the span measured before a hand-over
  double margin = 1.5;            // IDA's cost over Euler's that hands the run over
  double ida_step_cost = 6.0;     // [force sweeps] per IDA step
  double ida_restart_cost = 10.0; // [force sweeps] per IDA restart
  double euler_step_cost = 1.1;   // [force sweeps] per Euler step
  bool require_resolution = true; // condition (2): IDA's mean step at least Euler's
  bool require_closed_joints = true;  // condition (3): Euler's joints within the trial's limit under their loads
  // Euler on trial: IDA takes the run back past either (half the accuracy warnings' limits,
  // kEnergyShareLimit and kConstraintResidualLimit in results/accuracy_check.hpp).
  double euler_energy_share = 0.005;   // [-] Euler's drift since the hand-over over the energy turned over
  double euler_joint_opening = 0.5e-3; // [m] |Phi| at an output sample
  long euler_check_steps = 50;         // [steps] Euler's checks come at every output sample and at least this often
};

class AutoIntegrator : public IdaIntegrator {
 public:
  AutoIntegrator(DaeSystem& system, IdaSettings ida, EulerSettings euler, AutoSettings rule = {});
  const char* name() const override { return integrator_name(IntegratorKind::Auto); }

 protected:
  void start(double t_end) override;
  std::unique_ptr<Integrator> hand_over(double t, const double* y) override;
  /// IDA failed: Euler takes the rest of the run from IDA's last good state, and the run says
  /// so (RunStatistics::hand_over_reason, summary.json's integrator_used). Null when Euler
  /// cannot run the model or already has the run.
  std::unique_ptr<Integrator> rescue(const std::string& failure, double* t) override;
  void finish() override;
  /// Euler gave the run back (its trial failed): IDA goes on from its state.
  void resume(double t, std::vector<double> y, const std::vector<double>& quadratures) override;

 public:
  /// The trial's limit on Euler's joints, rule.euler_joint_opening in the model's length unit.
  static double joint_opening_limit(const DaeSystem& system, const AutoSettings& rule) {
    return rule.euler_joint_opening / metres_per_length_unit(system.model().units);
  }

 private:
  double joint_opening_limit() const { return joint_opening_limit(system_, rule_); }
  /// How far Euler's penalty joints would stand open [length] carrying the multipliers of IDA's
  /// state y (|lambda| / k, the largest over the rows).
  double penalty_opening(const double* y) const;

 private:
  AutoSettings rule_;
  EulerSettings euler_settings_;
  std::optional<EulerIntegrator::Step> euler_step_;  // null: Euler cannot run this model (euler_refusal_)
  std::string euler_refusal_;
  long steps_ = 0;            // IDA steps so far
  double window_t_ = 0.0;     // [time] where the measured span begins (after the startup steps)
  long window_restarts_ = 0;  // restarts before it
  double ida_cost_ = 0.0, euler_cost_ = 0.0;  // [force sweeps] over the span so far
  double ida_mean_step_ = 0.0;                // [time] over the span so far
  double t_end_ = 0.0;                        // [time] the run's
  double joints_would_open_ = 0.0;            // [length] penalty_opening at the last hand-over that passed (1) and (2)
  bool euler_taking_over_ = false;  // hand_over returned Euler: finish() keeps IDA's objects (suspend)
  double ida_last_step_ = 0.0;      // [time] IDA's last step before the hand-over (the first after a resume)
};

}  // namespace railcrash
