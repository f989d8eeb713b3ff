// IDA (SUNDIALS IDAS: IDA plus quadratures) on the GGL DAE with the KLU sparse solver.
//
// * Consistent start: position assembly and velocity projection (initial_conditions.hpp),
//   then accelerations and multipliers from the acceleration-level system (consistent_rates;
//   IDACalcIC cannot find them for the GGL form, see initial_conditions.hpp).
// * Tolerances per component: velocities rtol |v| + 0.1 rtol V (or rtol |v| + atol V / L);
//   positions, by simulation: position_tolerance, relative (default; IDASVtolerances):
//   rtol |q| + 0.1 rtol L (or rtol |q| + atol), or absolute (IDAWFtolerances): atol alone,
//   by default rtol V / omega (omega the highest natural frequency, from Euler's stability
//   limit), at most 0.1 rtol L; angles get the length tolerance over their body's size;
//   multipliers lambda rtol |lambda| + min(1, max(100 rtol, 1e-5)) F and mu rtol |mu| + V (see
//   the comment in start()), where L is the model's extent (absolute: the box around its bodies
//   and ground points), F its largest initial generalized force and V the larger of its
//   initial speeds and sqrt(2 E / M) with E = max(initial kinetic energy, F L).
// * IDASetId marks q, v differential and lambda, mu algebraic; IDASetSuppressAlg keeps the
//   algebraic unknowns out of the error test.
// * Quadratures (kinetic-energy integral, load work, element work) with error control.
// * Events: IDA takes one step at a time; after each step every root function is evaluated
//   once and a root that fell through zero is located element by element on IDA's own
//   interpolating polynomial (its Taylor form at t_n from IDAGetDky, evaluated only for the
//   unknowns the element reads), so locating an event costs the same in any model size. The
//   bookkeeping and the location are the event layer's (events.hpp: ModeTracker,
//   EventLocator, owned by the run loop's Integrator); IDA gives it a StepInterpolant.
//   Events are committed in time order; IDA goes on without a restart when the new law agrees
//   with the old one over the rest of the step within the local tolerances (kinks), and
//   restarts from consistent values at the event otherwise (jumps, joint failures).
// * KLU: the symbolic analysis is kept across restarts, the pivot order across Jacobian
//   updates; its growth is checked at the setup after a failed Newton iteration, where a
//   stale order would show (klu_solver.hpp).
// * Every SUNDIALS return code is checked; failures become SolverError with the flag's name.
//   Callbacks never let an exception into SUNDIALS: they store it and return -1.
#pragma once

#include <memory>

#include "railcrash/model/run_spec.hpp"  // the integrators' names (IntegratorKind), rtol_problem
#include "railcrash/solver/integrator.hpp"

namespace railcrash {

struct IdaSettings {
  double rtol = 1e-6;
  std::optional<double> atol;  // [length]
  PositionTolerance position_tolerance = PositionTolerance::Relative;
  LinearOrdering linear_ordering = LinearOrdering::FewestEntries;  // KLU's fill-reducing ordering
  long max_steps_per_output = 500000;
  // A Jacobian evaluated at a setup serves IDA's later setups for up to this many steps, its
  // rates' part changed to the new cj (DaeSystem::add_rate_jacobian), while no element has
  // changed mode and IDA's Newton iteration has not failed since (as CVODE's linear solver
  // interface keeps its Jacobian; IDA's own evaluates one at every setup). 0: a Jacobian at
  // every setup (simulation: jacobian_kept_steps; README "Jacobians kept"; bench/HISTORY.md,
  // "The Jacobian kept between setups").
  long jacobian_kept_steps = kDefaultJacobianKeptSteps;  // [steps]
  long max_steps = 10000000;  // [steps] in the whole run; the run fails (not ok) beyond
  CommonRunSettings run;      // t_end, static_equilibrium
};

class IdaIntegrator : public Integrator {
 public:
  IdaIntegrator(DaeSystem& system, IdaSettings settings);
  ~IdaIntegrator() override;
  const char* name() const override { return integrator_name(IntegratorKind::Ida); }
  // Newton iterations IDA may take per step once its iteration has failed to converge in a
  // run (SUNDIALS' default, 4, until then; take_step says why).
  static constexpr int kPatientNewtonIterations = 20;
  // BDF orders 3 to 5 are not A-stable: a lightly damped oscillation that a loose tolerance
  // resolves coarsely can grow under them, and the integration creates energy. Once it has
  // created kCreatedEnergyShare of the energy turned over (DaeSystem::work_balance, after every step of
  // order 3 or more), IDA restarts there with its order held to kHeldOrder (BDF2, A-stable)
  // for the rest of the run (hold_order_if_energy_created; bench/HISTORY.md, "BDF order held
  // where the integration creates energy").
  static constexpr double kCreatedEnergyShare = 2e-2;  // [-] of the energy turned over: twice the accuracy warning's
  // ... or once it has created kCreatedInOneCheckShare since the previous check: growth, not a
  // coarse run's drift swinging through (the BDF5 step that created 9 % of the barrier cars'
  // energy at once came after one that created 2.7 %).
  static constexpr double kCreatedInOneCheckShare = 1e-2;  // [-] of the energy turned over
  static constexpr int kHeldOrder = 2;
  static constexpr int kAllocatedOrder = 5;  // SUNDIALS' default maximum order, which IDAInit allocates for

  struct Impl;

 protected:
  // Integrator's steps (integrator.hpp).
  void start(double t_end) override;
  double advance(double t_end) override;
  bool dense_output() const override { return true; }
  void state_at(double t, std::vector<double>& y, std::vector<double>& quadratures) override;
  const double* current_state() const override;
  const double* current_outputs() const override { return outputs_current_ ? outputs_.data() : nullptr; }
  void final_state(std::vector<double>& y, std::vector<double>& quadratures) override;
  std::string step_limit_advice(double t_end) const override;
  std::string divergence_phrase() const override { return "IDA's solution is not finite"; }
  long max_steps() const override { return settings_.max_steps; }
  void finish() override;
  /// IDA's current time: after a failed step, the time of its last good state (state_at there).
  double current_time() const;
  /// At a hand-over that may come back (integrator auto): IDA's counters and KLU's figures
  /// into stats(), as finish() puts them, with SUNDIALS' objects kept for resume_at.
  void suspend();
  /// Goes on at t from a successor's state y (positions and velocities; its multipliers are
  /// replaced) and quadratures, with the tolerances, Jacobian pattern and KLU analysis of the
  /// run so far (suspend()): the joints closed by the start's assembly, consistent rates in the
  /// present modes, and the one restart, its first step a fraction of step_before. Throws
  /// StepFailure when the joints cannot be closed.
  void resume_at(double t, std::vector<double> y, const std::vector<double>& quadratures, double step_before, double t_end);

 private:
  friend class IdaEventHandler;  // (ida_integrator.cpp) IDA's side of the event loop
  /// Before the first step: InputError naming the element or body whose residual, Jacobian or
  /// rates are not finite (or so large that IDA's norms overflow) at t = 0.
  void check_start(const double* y, const double* yp, double t_end) const;
  /// Why IDA failed, in the model's terms: a non-finite residual's element or body, a
  /// singular configuration of the joints, the unknowns with the largest weighted errors.
  std::string explain_failure(int flag);
  /// IDA's next step (IDA_ONE_STEP, with one retry of a failed first step after a restart);
  /// the time it reached. Throws StepFailure.
  double take_step(double t_end);
  /// After a step from t_step_start to t_n: its roots, and the crossings in it located and
  /// committed in time order (events.hpp, event_loop.hpp: IDA's decisions are an
  /// IdaEventHandler's); kinks within tolerance go on, a jump restarts at its event (then
  /// true: the step's end is discarded).
  bool handle_events(double t_step_start, double t_n, double t_end);
  /// After a step to t_n that did not restart: when the integration has created more than
  /// kCreatedEnergyShare of the energy turned over since IDA started (or took the run back),
  /// holds IDA's BDF order to kHeldOrder from t_n, with a restart there (IDA keeps no history
  /// of a higher order then); stats().bdf_order_held_at says where. Once per run.
  void hold_order_if_energy_created(double t_n, double t_end);
  /// Restarts IDA at crossing c's event (state y_at_event): consistent rates in the new modes
  /// (and boundary commits there), quadratures interpolated, the one restart (Impl::restart).
  void restart_at_event(const Crossing& c, const double* y_at_event, double t_end);
  /// The one restart, from an event or a take-back: consistent rates for y in the present
  /// modes at t and the boundary commits there (changed: the elements that already changed
  /// at t; the commits are appended to events and reported), then Impl::restart with its first
  /// step from step_before (kept for one retry), the roots armed. add_counters: IDA's counters
  /// go to the statistics first (false after suspend, which put them there).
  void restart_from(double t, std::vector<double> y, std::vector<char> changed, std::vector<double> quadratures,
                    double step_before, std::vector<EventRecord>& events, double t_end, bool add_counters);
  /// Whether element e's mode change at t_event (its load in the old modes `before`: at the
  /// event and at t_n) leaves IDA's step to t_n within the local tolerances without a restart
  /// (the lag test; see advance()). quadratures: at t_n.
  bool lag_within_tolerance(int e, const std::array<DaeSystem::ElementLoad, 2>& before, double t_event,
                            const double* y_at_event, double t_n, const double* y_n, const double* quadratures,
                            double weight_at_event = 0.5, double weight_at_n = 0.5) const;
  /// "; the largest force on it, F, comes from FILE:LINE: element 'NAME' (TYPE)" for body unknown k at t = 0.
  std::string largest_force_on(int k, const double* y) const;

  IdaSettings settings_;
  std::unique_ptr<Impl> impl_;  // SUNDIALS' objects of the run in progress
  std::vector<double> outputs_;  // element outputs at the step's end, from the roots' sweep
  bool outputs_current_ = false;  // outputs_ belong to current_state() and the present modes
};

}  // namespace railcrash
