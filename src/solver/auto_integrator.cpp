#include "railcrash/solver/auto_integrator.hpp"

#include <cmath>
#include <cstdio>

namespace railcrash {

namespace {

/// Euler after IDA's hand-over, on trial (auto_integrator.hpp): at each new output sample and
/// every rule.euler_check_steps steps, its energy drift since the hand-over and its joints'
/// opening against the rule's limits; past either it gives the run back (returns_run).
class EulerOnTrial final : public EulerIntegrator {
 public:
  EulerOnTrial(DaeSystem& system, const EulerSettings& settings, Step step, double t0, const std::vector<double>& y,
               const std::vector<double>& quadratures, const AutoSettings& rule, double drift_at_hand_over)
      : EulerIntegrator(system, settings, std::move(step), t0, y, quadratures),
        energy_share_(rule.euler_energy_share),
        joint_opening_(AutoIntegrator::joint_opening_limit(system, rule)),
        drift_at_hand_over_(drift_at_hand_over),
        check_steps_(rule.euler_check_steps) {}

  bool returns_run(double t, const double* /*y*/, bool sample_here) override {
    // Before each sample (taken at this step's end: Euler samples there), so that a state past
    // the limits is never written, and every check_steps steps between samples far apart.
    if (!sample_here && ++steps_since_check_ < check_steps_) return false;
    steps_since_check_ = 0;
    state_for_successor(t, state_, quadratures_);
    const EnergyBalance balance = EnergyBalance::between(run_initial_energy(), energy(state_.data(), quadratures_.data()));
    const double drift = balance.integration_drift() - drift_at_hand_over_;  // [energy] Euler's own
    const double turned_over = balance.turned_over();
    const double share = turned_over > 0.0 ? std::abs(drift) / turned_over : 0.0;
    const double opening = system_.constraint_residual(state_.data(), phi_);
    char why[300];
    if (share > energy_share_)
      std::snprintf(why, sizeof why, "its integration had %s %.4g %% of the energy turned over since (more than %.4g %%)",
                    drift < 0.0 ? "created" : "lost", 100.0 * share, 100.0 * energy_share_);
    else if (opening > joint_opening_)
      std::snprintf(why, sizeof why, "its penalty joints opened by %.3g length units (more than %.3g)", opening,
                    joint_opening_);
    else
      return false;
    char reason[420];
    std::snprintf(reason, sizeof reason, "; IDA took the run back at t = %.6g, where Euler was less accurate than "
                  "the accuracy warnings allow: %s", t, why);
    stats().hand_over_reason += reason;
    stats().handed_back_at = t;
    return true;
  }

 private:
  double energy_share_;        // [-]
  double joint_opening_;       // [length]
  double drift_at_hand_over_;  // [energy] the run's integration drift when Euler took it
  long check_steps_;           // [steps] the most between two checks
  long steps_since_check_ = 0;
  std::vector<double> state_, quadratures_, phi_;  // at the check
};

}  // namespace

AutoIntegrator::AutoIntegrator(DaeSystem& system, IdaSettings ida, EulerSettings euler, AutoSettings rule)
    : IdaIntegrator(system, ida), rule_(rule), euler_settings_(euler) {}

void AutoIntegrator::start(double t_end) {
  IdaIntegrator::start(t_end);
  t_end_ = t_end;
  euler_taking_over_ = false;
  ida_last_step_ = 0.0;
  steps_ = 0;
  window_t_ = 0.0;
  window_restarts_ = 0;
  ida_cost_ = euler_cost_ = ida_mean_step_ = 0.0;
  joints_would_open_ = 0.0;
  euler_step_.reset();
  euler_refusal_.clear();
  // Euler's step from the state IDA starts from (assembled and settled), as a plain Euler run
  // would choose it.
  const std::vector<double> y0(current_state(), current_state() + system_.size());
  try {
    EulerIntegrator::Step step = EulerIntegrator::choose_step(system_, y0, euler_settings_);
    euler_refusal_ = EulerIntegrator::refusal(system_, step, euler_settings_, 0.0);
    if (euler_refusal_.empty()) euler_step_ = std::move(step);
  } catch (const InputError& e) {
    euler_refusal_ = e.what();
  }
}

double AutoIntegrator::penalty_opening(const double* y) const {
  // Euler's penalty force on row r is k_r Phi_r + c_r Phi_r', IDA's the multiplier lambda_r:
  // carrying the same load at rest, the joint stands open by |lambda_r| / k_r (an angle row
  // counted at its bodies' size, DaeSystem::constraint_row_length, as the constraint residual counts it).
  const int nq = system_.body_unknowns();
  const std::vector<double>& stiffness = euler_step_->penalty.stiffness;
  double widest = 0.0;  // [length]
  for (int row = 0; row < system_.constraint_rows(); ++row) {
    const double k = stiffness[static_cast<std::size_t>(row)];
    if (!(k > 0.0)) continue;
    widest = std::max(widest, std::abs(y[2 * nq + row]) / k * system_.constraint_row_length(row));
  }
  return widest;
}

std::unique_ptr<Integrator> AutoIntegrator::hand_over(double t, const double* y) {
  if (!euler_step_) return nullptr;
  if (++steps_ <= rule_.startup_steps) {
    window_t_ = t;
    window_restarts_ = stats().reinitializations;
    return nullptr;
  }
  const double dt = euler_step_->dt;
  const auto span_steps = static_cast<double>(steps_ - rule_.startup_steps);
  ida_cost_ = rule_.ida_step_cost * span_steps +
              rule_.ida_restart_cost * static_cast<double>(stats().reinitializations - window_restarts_);
  euler_cost_ = rule_.euler_step_cost * (t - window_t_) / dt;
  ida_mean_step_ = (t - window_t_) / span_steps;
  if (t - window_t_ < rule_.min_span_steps * dt || stats().events < rule_.min_events ||
      ida_cost_ <= rule_.margin * euler_cost_ || (rule_.require_resolution && ida_mean_step_ < dt))
    return nullptr;
  // (3) Euler's penalty joints would stand open within the trial's limit under the loads the
  // joints carry now (past it, the trial would give the run back at its first sample, with
  // that sample's joints open).
  if (rule_.require_closed_joints) {
    joints_would_open_ = penalty_opening(y);
    if (joints_would_open_ > joint_opening_limit()) return nullptr;
  }
  std::vector<double> state, quadratures;
  state_for_successor(t, state, quadratures);
  const double drift = EnergyBalance::between(run_initial_energy(), energy(state.data(), quadratures.data())).integration_drift();
  auto euler = std::make_unique<EulerOnTrial>(system_, euler_settings_, std::move(*euler_step_), t, state, quadratures, rule_, drift);
  euler_step_.reset();
  euler_taking_over_ = true;
  char reason[400];
  std::snprintf(reason, sizeof reason,
                "IDA handed the run to Euler at t = %.6g: from t = %.6g its steps (mean %.4g) and restarts cost about "
                "%.0f force sweeps, Euler's steps of %.4g about %.0f, after %ld mode changes",
                t, window_t_, ida_mean_step_, ida_cost_, dt, euler_cost_, stats().events);
  stats().handed_over_at = t;
  stats().hand_over_reason = reason;
  return euler;
}

std::unique_ptr<Integrator> AutoIntegrator::rescue(const std::string& failure, double* t) {
  if (!euler_step_) return nullptr;
  std::vector<double> state, quadratures;
  double t_good = 0.0;
  try {
    t_good = current_time();
    state_for_successor(t_good, state, quadratures);
  } catch (const std::exception&) {
    return nullptr;  // no good state to go on from: the run fails with IDA's message
  }
  const double dt = euler_step_->dt;
  auto euler = std::make_unique<EulerIntegrator>(system_, euler_settings_, std::move(*euler_step_), t_good, state, quadratures);
  euler_step_.reset();
  stats().handed_over_at = t_good;
  char head[200];
  std::snprintf(head, sizeof head, "IDA failed; Euler (step %.4g) took the rest of the run from IDA's last good state at t = %.6g: ",
                dt, t_good);
  stats().hand_over_reason = head + failure;
  *t = t_good;
  return euler;
}

void AutoIntegrator::resume(double t, std::vector<double> y, const std::vector<double>& quadratures) {
  resume_at(t, std::move(y), quadratures, ida_last_step_, t_end_);
}

void AutoIntegrator::finish() {
  if (euler_taking_over_) {  // Euler takes the run on trial: IDA's objects are kept for the way back
    euler_taking_over_ = false;
    suspend();
    ida_last_step_ = stats().last_step;
    return;
  }
  IdaIntegrator::finish();
  if (stats().handed_over_at >= 0.0) return;  // the reason of the hand-over stands
  if (!euler_refusal_.empty()) {
    stats().hand_over_reason = "IDA kept the run: Euler cannot run this model (" + euler_refusal_ + ")";
    return;
  }
  if (steps_ <= rule_.startup_steps) {
    stats().hand_over_reason = "IDA kept the run: it ended within IDA's first " + std::to_string(rule_.startup_steps) + " steps";
    return;
  }
  const double dt = euler_step_ ? euler_step_->dt : 0.0;
  char joints[200];
  std::snprintf(joints, sizeof joints,
                "dearer, but Euler's penalty joints would stand open by %.3g length units under the joints' loads "
                "(more than %.3g)", joints_would_open_, joint_opening_limit());
  const char* why = ida_cost_ <= rule_.margin * euler_cost_ ? "cheaper or not clearly dearer"
                    : rule_.require_resolution && ida_mean_step_ < dt
                        ? "dearer, but its steps are shorter than Euler's: Euler would resolve the motion less finely"
                    : joints_would_open_ > joint_opening_limit() ? joints
                                                                 : "dearer, but with too few mode changes for a crash run";
  char reason[600];
  std::snprintf(reason, sizeof reason,
                "IDA kept the run: from t = %.6g its steps (mean %.4g) and restarts cost about %.0f force sweeps, Euler's "
                "steps of %.4g about %.0f: IDA %s",
                window_t_, ida_mean_step_, ida_cost_, dt, euler_cost_, why);
  stats().hand_over_reason = reason;
}

}  // namespace railcrash
