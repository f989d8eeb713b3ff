#include "railcrash/solver/euler_integrator.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "railcrash/solver/event_loop.hpp"
#include "railcrash/solver/initial_conditions.hpp"
#include "railcrash/solver/stability_limit.hpp"

namespace railcrash {

namespace {

constexpr double kPenaltyStepAngle = 0.4;  // penalty circular frequency times dt

}  // namespace

PenaltyRows EulerIntegrator::make_penalty(const DaeSystem& system, const Element::PenaltyOverrides& global, double dt) {
  const int m = system.constraint_rows();
  PenaltyRows rows;
  rows.stiffness.assign(static_cast<std::size_t>(m), 0.0);
  rows.damping.assign(static_cast<std::size_t>(m), 0.0);
  // Effective mass of each row, bounded over all orientations of the bodies
  // (DaeSystem::constraint_row_inverse_mass_bounds).
  const std::vector<double> inverse_effective_mass = system.constraint_row_inverse_mass_bounds();
  const double rate = kPenaltyStepAngle / dt;
  for (int r = 0; r < m; ++r) {
    const auto row = static_cast<std::size_t>(r);
    const bool rotational = system.constraint_row_is_rotational(r);
    const double effective_mass = 1.0 / inverse_effective_mass[row];
    const Element::PenaltyOverrides& own = system.constraint_row_penalty(r);
    const std::optional<double> k = rotational ? (own.rotational_stiffness ? own.rotational_stiffness : global.rotational_stiffness)
                                               : (own.stiffness ? own.stiffness : global.stiffness);
    const std::optional<double> c = rotational ? (own.rotational_damping ? own.rotational_damping : global.rotational_damping)
                                               : (own.damping ? own.damping : global.damping);
    rows.stiffness[row] = k ? *k : effective_mass * rate * rate;
    rows.damping[row] = c ? *c : 2.0 * effective_mass * rate;
  }
  return rows;
}

namespace {

/// Why a step dt that needs more than max_steps steps from t0 to the run's t_end cannot run ("" when it can).
std::string step_count_problem(const Model& model, double t_end, double dt, long max_steps, double t0) {
  const double steps_needed = std::ceil((t_end - t0) / dt - 1e-9);  // [steps], a double: never overflows
  if (steps_needed <= static_cast<double>(max_steps)) return "";
  std::ostringstream msg;
  msg << SourceLocation{model.file, 0}.prefix() << "explicit Euler with dt = " << dt << " needs " << steps_needed
      << " steps to reach t_end = " << t_end << ", more than --max-steps " << max_steps
      << "; use a larger dt (above " << t_end / static_cast<double>(max_steps)
      << "), a shorter t_end, or raise --max-steps";
  return msg.str();
}

/// Why a body without inertia stops Euler ("" when every body has one).
std::string inertia_problem(const Model& model) {
  for (const Body& b : model.bodies())
    if (!(b.inertia > 0.0))
      return b.where.prefix() + "body '" + b.name +
             "' has zero inertia: explicit Euler needs every body's inertia to be positive "
             "(use integrator: ida, or give the body an inertia)";
  return "";
}

void throw_if(const std::string& problem) {
  if (!problem.empty()) throw InputError(problem);
}

}  // namespace

EulerIntegrator::Step EulerIntegrator::choose_step(const DaeSystem& system, const std::vector<double>& y,
                                                   const EulerSettings& settings) {
  if (settings.dt < 0.0 || !std::isfinite(settings.dt)) throw InputError("dt must be a positive step (or 0 for automatic)");
  Step step;
  if (settings.dt > 0.0) {
    step.dt = settings.dt;
    // Before penalties sized for a dt that cannot run.
    throw_if(step_count_problem(system.model(), settings.run.t_end, step.dt, settings.max_steps, 0.0));
    step.penalty = make_penalty(system, settings.penalty, step.dt);
    step.stability_limit = explicit_stability_limit(system, y, &step.penalty);
    return step;
  }
  // Automatic: half the limit of the elements alone, then penalties for that step; shrink
  // once more if the penalties lowered the limit.
  const double physical_limit = explicit_stability_limit(system, y, nullptr);
  step.dt = std::isfinite(physical_limit) ? 0.5 * physical_limit : 1e-3 * settings.run.t_end;
  for (int pass = 0; pass < 20; ++pass) {
    step.penalty = make_penalty(system, settings.penalty, step.dt);
    step.stability_limit = explicit_stability_limit(system, y, &step.penalty);
    if (step.dt <= 0.8 * step.stability_limit) break;
    step.dt = 0.5 * step.stability_limit;
  }
  return step;
}

std::string EulerIntegrator::refusal(const DaeSystem& system, const Step& step, const EulerSettings& settings, double t0) {
  std::string problem = inertia_problem(system.model());
  if (!problem.empty()) return problem;
  if (step.dt > step.stability_limit && !settings.force_dt) {
    std::ostringstream msg;
    msg << "the Euler step dt = " << step.dt << " is above the stability limit " << step.stability_limit
        << " of this model (largest stable step, penalty joints included); use dt <= " << step.stability_limit
        << " (e.g. --dt " << 0.5 * step.stability_limit << "), or --force-dt to run anyway";
    return msg.str();
  }
  return step_count_problem(system.model(), settings.run.t_end, step.dt, settings.max_steps, t0);
}

EulerIntegrator::EulerIntegrator(DaeSystem& system, EulerSettings settings)
    : Integrator(system), settings_(settings) {
  throw_if(inertia_problem(system.model()));
  mode_tracker().set_run_end(settings_.run.t_end);
  const StartReport start = prepare_start(system, y0_, start_events_, settings_.run.static_equilibrium);
  start_modes_ = mode_tracker().snapshot();
  assembly_correction_ = start.assembly.largest_position_change;
  settling_steps_ = start.equilibrium.steps;
  settling_displacement_ = start.equilibrium.largest_position_change;
  Step step = choose_step(system, y0_, settings_);
  throw_if(refusal(system, step, settings_, 0.0));
  dt_ = step.dt;
  stability_limit_ = step.stability_limit;
  penalty_ = std::move(step.penalty);
}

EulerIntegrator::EulerIntegrator(DaeSystem& system, EulerSettings settings, Step step, double t0,
                                 const std::vector<double>& y, const std::vector<double>& quadratures)
    : Integrator(system), settings_(settings), dt_(step.dt), stability_limit_(step.stability_limit),
      penalty_(std::move(step.penalty)) {
  mode_tracker().set_run_end(settings_.run.t_end);
  throw_if(refusal(system, Step{dt_, stability_limit_, {}}, settings_, t0));
  y_ = y;
  quadratures_ = quadratures;
  begin(t0, false);  // the run's observer is not ours yet: no events to report here
}

void EulerIntegrator::continue_from_hand_over() {
  stats().stability_limit = stability_limit_;
  stats().last_step = dt_;
  stats().euler_step = dt_;
}

void EulerIntegrator::start(double /*t_end*/) {
  stats().stability_limit = stability_limit_;
  stats().assembly_correction = assembly_correction_;
  stats().settling_steps = settling_steps_;
  stats().settling_displacement = settling_displacement_;
  stats().last_step = dt_;
  stats().euler_step = dt_;
  y_ = y0_;
  quadratures_.assign(static_cast<std::size_t>(system_.quadrature_count()), 0.0);
  // Modes as prepared (and settled) in the constructor; a second run starts from them too.
  mode_tracker().restore(start_modes_);
  begin(0.0, true);
}

void EulerIntegrator::begin(double t0, bool run_start) {
  const int nq = system_.body_unknowns();
  const int m = system_.constraint_rows();
  const int nquad = system_.quadrature_count();
  force_.assign(static_cast<std::size_t>(nq), 0.0);
  rates_.assign(static_cast<std::size_t>(nquad), 0.0);
  lambda_.assign(static_cast<std::size_t>(m), 0.0);
  inverse_mass_.resize(static_cast<std::size_t>(nq));
  for (int k = 0; k < nq; ++k) inverse_mass_[static_cast<std::size_t>(k)] = 1.0 / system_.mass_diagonal(k);
  t_ = t0;
  t0_ = t0;
  step_ = 0;
  double* q = y_.data();
  double* v = y_.data() + nq;
  // The multipliers' place in y (for output) holds the penalty forces.
  system_.generalized_forces(t0, q, v, force_.data(), &penalty_, lambda_.data());
  std::copy(lambda_.begin(), lambda_.end(), y_.begin() + 2 * nq);
  // Mode changes: the same root functions as IDA, checked at the end of every step (what
  // IITRAIN's "internal logic checks at each time step" did) by the event layer on a step
  // known at its end alone (EulerStep). A root that sits at zero right after its commit is
  // ignored until it leaves zero.
  ModeTracker& modes = mode_tracker();
  const int root_count = system_.root_count();
  modes.previous().assign(static_cast<std::size_t>(root_count), 0.0);
  modes.now() = modes.previous();
  if (run_start) report_events(start_events_, y_.data());
  if (root_count > 0 && run_start) {
    // A state that starts exactly on a mode boundary and moves out of the mode (same rule as IDA's restart).
    EulerStep step(*this, t0, t0);
    std::vector<double> yp(y_.size(), 0.0);
    step.rates_at(t0, yp.data());
    events_.clear();
    if (modes.commit_boundary(0.0, y_.data(), yp.data(), events_)) report_events(events_, y_.data());
  }
  outputs_.assign(system_.output_names().size(), 0.0);
  sweep();
  modes.end_step();
}

const double* EulerIntegrator::EulerStep::state_at(double /*t*/) { return euler_.y_.data(); }

void EulerIntegrator::EulerStep::unknowns_at(const std::vector<int>& unknowns, double /*t*/, double* y) {
  for (const int i : unknowns) y[i] = euler_.y_[static_cast<std::size_t>(i)];
}

void EulerIntegrator::EulerStep::rates_at(double /*t*/, double* yp) {
  // q' = v and v' = M^-1 f at the step's end (the last sweep's forces); the multipliers' rates 0.
  const int nq = euler_.system_.body_unknowns();
  std::fill(yp, yp + euler_.y_.size(), 0.0);
  for (int k = 0; k < nq; ++k) {
    yp[k] = euler_.y_[static_cast<std::size_t>(nq + k)];
    yp[nq + k] = euler_.force_[static_cast<std::size_t>(k)] * euler_.inverse_mass_[static_cast<std::size_t>(k)];
  }
}

void EulerIntegrator::sweep() {
  const int nq = system_.body_unknowns();
  DaeSystem::SweepExtras extras;
  extras.powers = rates_.data();
  extras.roots = mode_tracker().now().data();
  // The outputs the observers' step() reads (the rows evaluate all of theirs): none when no
  // observer takes steps, else those of the elements step_output_elements() names.
  extras.outputs = step_outputs_wanted() ? outputs_.data() : nullptr;
  extras.output_elements = step_output_elements();
  extras.y_lambda = y_.data() + 2 * nq;  // the roots and outputs see y's multipliers, as roots(t, y) does
  const PhaseClock::Scope timed(phase_clock(), Phase::Residual);
  system_.generalized_forces(t_, y_.data(), y_.data() + nq, force_.data(), &penalty_, lambda_.data(), nullptr, &extras);
  outputs_current_ = extras.outputs != nullptr;
}

/// Euler's decisions about the mode changes at its step's end (event_loop.hpp): the observers
/// look at the old modes there; after a change, the step's end is swept again in the new modes
/// (forces, roots into the mode tracker's now(), outputs) and the events reported.
class EulerEventHandler final : public EventHandler {
 public:
  explicit EulerEventHandler(EulerIntegrator& euler) : euler_(euler) {}
  void before_change(const Crossing& c, const double* y_at_event) override { euler_.observe_before_event(c.t, y_at_event); }
  bool goes_on_across(const Crossing& /*c*/, const double* /*y_at_event*/, const std::vector<EventRecord>& /*events*/) override {
    return false;  // (not asked on a step known at its end alone)
  }
  void restart_at(const Crossing& /*c*/, const double* /*y_at_event*/) override {
    ++euler_.stats().reinitializations;
    euler_.sweep();
    euler_.report_events(euler_.events_, euler_.y_.data());
  }

 private:
  EulerIntegrator& euler_;
};

// The loop runs on time: step k ends at t0 + k dt (no drift), the last one at t_end exactly.
double EulerIntegrator::advance(double t_end) {
  const int nq = system_.body_unknowns();
  const int nquad = system_.quadrature_count();
  double* q = y_.data();
  double* v = y_.data() + nq;
  ++step_;
  const bool last = static_cast<double>(step_) >= (t_end - t0_) / dt_ - 1e-9;
  const double t_next = last ? t_end : t0_ + static_cast<double>(step_) * dt_;
  const double t_start = t_;
  const double h = t_next - t_start;
  // force_, rates_ and lambda_ at (t_, y_) come from the last sweep (start() or the last step).
  outputs_current_ = false;
  for (int k = 0; k < nquad; ++k) quadratures_[static_cast<std::size_t>(k)] += h * rates_[static_cast<std::size_t>(k)];
  for (int k = 0; k < nq; ++k) {
    v[k] += h * force_[static_cast<std::size_t>(k)] * inverse_mass_[static_cast<std::size_t>(k)];
    q[k] += h * v[k];
  }
  t_ = t_next;
  ++stats().steps;
  stats().residual_evaluations += 1;
  std::copy(lambda_.begin(), lambda_.end(), y_.begin() + 2 * nq);
  sweep();  // the next step's forces, this state's roots (into the mode tracker's now()) and outputs
  ModeTracker& modes = mode_tracker();
  if (modes.root_count() > 0) {
    // The step is known at its end alone: the event loop commits its crossings there, all at once.
    EventLocator& locator = event_locator();
    if (locator.queue_step_end_crossings(t_, modes.previous(), modes.now())) {
      const PhaseClock::Scope timed(phase_clock(), Phase::Events);
      EulerStep step(*this, t_start, t_);
      EulerEventHandler handler(*this);
      commit_crossings(step, step.state_at(step.t1()), modes, locator, handler, 0.0, events_);
    } else {
      modes.end_step();
    }
  }
  return t_;
}

void EulerIntegrator::state_at(double /*t*/, std::vector<double>& y, std::vector<double>& quadratures) {
  y = y_;
  quadratures = quadratures_;
}

EnergyState EulerIntegrator::energy(const double* y, const double* quadratures) const {
  return system_.energy(y, quadratures, &penalty_);
}

std::string EulerIntegrator::step_limit_advice(double t_end) const {
  std::ostringstream text;
  text << " of dt = " << dt_ << ", before t_end = " << t_end << "; use a larger dt or raise --max-steps";
  return text.str();
}

std::string EulerIntegrator::divergence_advice(const std::vector<double>& last_good, double t_last_good) const {
  std::ostringstream text;
  text << "; the step " << dt_ << " is too large for the model as it deforms (stability limit at the start: "
       << stability_limit_ << ")";
  // A penalty joint that went unstable shows as the largest violation of its constraint in the
  // last good sample (its arms or effective masses changed since the penalties were sized).
  const int m = system_.constraint_rows();
  if (m == 0 || last_good.empty()) return text.str();
  std::vector<double> phi(static_cast<std::size_t>(m));
  system_.constraints(last_good.data(), phi.data(), nullptr);
  int worst = -1;
  double worst_violation = 0.0;  // [length]
  for (int r = 0; r < m; ++r) {
    if (!system_.constraint_row_active(r)) continue;
    const double violation = std::abs(phi[static_cast<std::size_t>(r)]) * system_.constraint_row_length(r);
    if (violation > worst_violation) worst_violation = violation, worst = r;
  }
  if (worst < 0) return text.str();
  text << "; the largest joint violation at the last good sample (t = " << t_last_good << ") is " << worst_violation
       << " (length units) in " << system_.element_label(system_.constraint_row_owner(worst), "joint")
       << ", likely the penalty that went unstable: give it (or the model) penalty_stiffness / penalty_damping "
          "for its present arms and masses, or a smaller dt";
  return text.str();
}

}  // namespace railcrash
