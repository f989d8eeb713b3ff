// The report's integrator: explicit Euler (IITRAIN's EULR module), in its velocity-first
// form (semi-implicit / Euler-Cromer: v += dt M^-1 f(t, q, v); q += dt v), first order.
// It drives the same element code as IDA. Constraints become penalty spring-dampers,
//   lambda = k Phi + c G v,  force on the bodies -G^T lambda,
// per constraint row. Defaults: k = m_eff (0.4 / dt)^2 and c = 2 m_eff (0.4 / dt) (critical
// damping at 0.4 rad per step), with m_eff the row's effective mass bounded over all body
// orientations (1/m_eff = sum over its bodies of 1/m + a^2/J, a the joint point's distance
// from the centre of mass; angle rows: sum of 1/J),
// so the penalty error falls as dt^2 and the penalty stiffness grows without bound as dt -> 0.
// Joint keys / simulation keys penalty_stiffness, penalty_damping (translational rows) and
// penalty_rotational_stiffness, penalty_rotational_damping (angle rows) override them.
//
// Stability: the scheme is stable below explicit_stability_limit (stability_limit.hpp: from
// the model's stiffest and most damped modes at the start, penalties included).
#pragma once

#include "railcrash/model/run_spec.hpp"  // the integrators' names (IntegratorKind)
#include "railcrash/solver/integrator.hpp"

namespace railcrash {

struct EulerSettings {
  double dt = 0.0;          // [time]; 0 = half the stability limit
  bool force_dt = false;    // run even when dt exceeds the stability limit
  Element::PenaltyOverrides penalty;  // model-wide defaults (a joint's own keys win)
  long max_steps = 10000000;          // [steps]; a t_end (run.t_end) that needs more is refused
  CommonRunSettings run;              // t_end, static_equilibrium
};

class EulerIntegrator : public Integrator {
 public:
  /// The step Euler takes on a model from state y: settings.dt, or half the stability limit
  /// of the elements with penalties sized for that step (lowered until the penalties keep it
  /// stable), and the penalty rows for it.
  struct Step {
    double dt = 0.0;               // [time]
    double stability_limit = 0.0;  // [time] largest stable step, penalties included
    PenaltyRows penalty;
  };
  static Step choose_step(const DaeSystem& system, const std::vector<double>& y, const EulerSettings& settings);
  /// Why Euler cannot run this model with these settings from state y ("" when it can): a
  /// body without inertia, a step above the stability limit (without force_dt), more steps
  /// than max_steps from t0 to t_end. The messages the constructor throws.
  static std::string refusal(const DaeSystem& system, const Step& step, const EulerSettings& settings, double t0);

  EulerIntegrator(DaeSystem& system, EulerSettings settings);
  /// Euler going on with a run another integrator took to t0 (Integrator::hand_over): from
  /// state y (q, v; the multipliers' place is overwritten by the penalty forces) and the
  /// quadratures there, in the element modes the system holds now, with the given step.
  EulerIntegrator(DaeSystem& system, EulerSettings settings, Step step, double t0, const std::vector<double>& y,
                  const std::vector<double>& quadratures);
  const char* name() const override { return integrator_name(IntegratorKind::Euler); }

  /// Step actually used and the stability limit (valid after construction).
  double step() const { return dt_; }
  double stability_limit() const { return stability_limit_; }
  const PenaltyRows& penalty() const { return penalty_; }

 protected:
  /// The system's energy figures with the penalty springs' stored energy and work.
  EnergyState energy(const double* y, const double* quadratures) const override;

 private:
  friend class EulerEventHandler;  // (euler_integrator.cpp) Euler's side of the event loop
  /// Euler's step for the event layer: known at its end alone (not dense), the state there.
  class EulerStep final : public StepInterpolant {
   public:
    EulerStep(EulerIntegrator& euler, double t0, double t1) : euler_(euler), t0_(t0), t1_(t1) {}
    double t0() const override { return t0_; }
    double t1() const override { return t1_; }
    bool dense() const override { return false; }
    /// The state at the step's end, whatever t.
    const double* state_at(double t) override;
    void unknowns_at(const std::vector<int>& unknowns, double t, double* y) override;
    /// q' = v, v' = M^-1 f from the last sweep's forces, at the step's end.
    void rates_at(double t, double* yp) override;

   private:
    EulerIntegrator& euler_;
    double t0_, t1_;
  };

  static PenaltyRows make_penalty(const DaeSystem& system, const Element::PenaltyOverrides& global, double dt);
  /// The run's state at t0 from y_ and quadratures_ in the present modes: forces, penalty
  /// forces, roots and outputs of the first step; at the run's start (run_start) also the
  /// start's mode changes and the roots that start on their boundary.
  void begin(double t0, bool run_start);
  void continue_from_hand_over() override;

  // Integrator's steps (integrator.hpp).
  void start(double t_end) override;
  double advance(double t_end) override;
  bool dense_output() const override { return false; }
  void state_at(double t, std::vector<double>& y, std::vector<double>& quadratures) override;
  const double* current_state() const override { return y_.data(); }
  const double* current_outputs() const override { return outputs_current_ ? outputs_.data() : nullptr; }
  /// One sweep over the elements at (t_, y_) in the present modes: the forces and power rates
  /// of the next step, the root functions into g_after_, the element outputs.
  void sweep();
  void final_state(std::vector<double>& y, std::vector<double>& quadratures) override { state_at(t_, y, quadratures); }
  std::string step_limit_advice(double t_end) const override;
  std::string divergence_phrase() const override { return "explicit Euler diverged"; }
  std::string divergence_advice(const std::vector<double>& last_good, double t_last_good) const override;
  long max_steps() const override { return settings_.max_steps; }

  EulerSettings settings_;
  std::vector<double> y0_;
  double dt_ = 0.0;
  double stability_limit_ = 0.0;
  double assembly_correction_ = 0.0;
  long settling_steps_ = 0;
  double settling_displacement_ = 0.0;
  std::vector<EventRecord> start_events_;  // mode changes while settling
  ElementStates::Snapshot start_modes_;    // element modes as prepared (and settled), where every run starts
  PenaltyRows penalty_;

  // The run in progress: y = [q, v, penalty forces] (the multipliers' place holds the
  // penalty forces of the last step), quadratures, time and step count.
  std::vector<double> y_, quadratures_;
  std::vector<double> force_, rates_, lambda_, inverse_mass_;
  std::vector<double> outputs_;             // element outputs at y_ (sweep())
  bool outputs_current_ = false;            // outputs_ belong to y_ and the present modes
  std::vector<EventRecord> events_;
  double t_ = 0.0;  // [time]
  double t0_ = 0.0;  // [time] where this integrator's steps began (0, or where it took over a run)
  long step_ = 0;    // steps since t0_
};

}  // namespace railcrash
