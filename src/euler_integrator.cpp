#include "railcrash/euler_integrator.hpp"

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "railcrash/initial_conditions.hpp"

namespace railcrash {

namespace {

constexpr double kPenaltyStepAngle = 0.4;  // penalty circular frequency times dt

/// Largest eigenvalue of the symmetric part of M^-1/2 A M^-1/2 (exact for small systems,
/// a Gershgorin upper bound otherwise).
double largest_scaled_eigenvalue(const std::vector<DaeSystem::Triplet>& a, const Eigen::VectorXd& inv_root_mass) {
  const int n = static_cast<int>(inv_root_mass.size());
  if (n <= 600) {
    Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(n, n);
    for (const auto& t : a) dense(t.row, t.col) += t.value;
    dense = 0.5 * (dense + dense.transpose()).eval();
    dense = inv_root_mass.asDiagonal() * dense * inv_root_mass.asDiagonal();
    if (n == 0) return 0.0;
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(dense, Eigen::EigenvaluesOnly);
    return std::max(0.0, eigen.eigenvalues().maxCoeff());
  }
  Eigen::SparseMatrix<double> sparse(n, n);
  std::vector<Eigen::Triplet<double>> entries;
  for (const auto& t : a) {
    const double v = 0.5 * t.value * inv_root_mass[t.row] * inv_root_mass[t.col];
    entries.emplace_back(t.row, t.col, v);
    entries.emplace_back(t.col, t.row, v);
  }
  sparse.setFromTriplets(entries.begin(), entries.end());
  double bound = 0.0;
  for (int k = 0; k < sparse.outerSize(); ++k) {
    double row_sum = 0.0;
    for (Eigen::SparseMatrix<double>::InnerIterator it(sparse, k); it; ++it) row_sum += std::abs(it.value());
    bound = std::max(bound, row_sum);
  }
  return bound;
}

}  // namespace

double EulerIntegrator::estimate_stability_limit(const DaeSystem& system, const std::vector<double>& y,
                                                 const PenaltyRows* penalty) {
  const int nq = system.body_unknowns();
  Eigen::VectorXd inv_root_mass(nq);
  for (int k = 0; k < nq; ++k) inv_root_mass[k] = 1.0 / std::sqrt(system.mass_diagonal(k));
  std::vector<DaeSystem::Triplet> df_dq, df_dv;
  system.force_jacobian(0.0, y.data(), y.data() + nq, penalty, df_dq, df_dv, /*stiffest=*/true);
  for (auto& t : df_dq) t.value = -t.value;  // K = -df/dq
  for (auto& t : df_dv) t.value = -t.value;  // C = -df/dv
  const double omega_squared = largest_scaled_eigenvalue(df_dq, inv_root_mass);
  const double damping_rate = largest_scaled_eigenvalue(df_dv, inv_root_mass);
  const double omega = std::sqrt(omega_squared);
  const double denominator = std::sqrt(omega * omega + 0.25 * damping_rate * damping_rate) + 0.5 * damping_rate;
  return denominator > 0.0 ? 2.0 / denominator : std::numeric_limits<double>::infinity();
}

PenaltyRows EulerIntegrator::make_penalty(double dt) const {
  const int m = system_.constraint_rows();
  const int nq = system_.body_unknowns();
  PenaltyRows rows;
  rows.stiffness.assign(static_cast<std::size_t>(m), 0.0);
  rows.damping.assign(static_cast<std::size_t>(m), 0.0);
  // Effective mass of each row, bounded over all orientations of the bodies: a translational
  // row moves body b's point at distance a_b from its centre, so 1 / m_eff <= sum 1/m_b + a_b^2/J_b;
  // an angle row gives sum 1/J_b. (Taken at the start only, (G M^-1 G^T)_rr would let the
  // penalty outrun the step once the bodies turn.)
  std::vector<double> inverse_effective_mass(static_cast<std::size_t>(m), 0.0);
  const Model& model = system_.model();
  for (std::size_t e = 0; e < model.elements().size(); ++e) {
    const Element& el = *model.elements()[e];
    for (int row = 0; row < el.constraint_count(); ++row) {
      double inverse = 0.0;
      for (int slot = 0; slot < 2; ++slot) {
        const int b = el.slot_body(slot);
        if (b == kGround) continue;
        const Body& body = model.bodies()[static_cast<std::size_t>(b)];
        double arm = 0.0;
        for (std::size_t p = 0; p < el.points().size(); ++p)
          if (el.point_slot(static_cast<int>(p)) == slot) arm = std::max(arm, std::hypot(el.points()[p].sx, el.points()[p].sy));
        inverse += el.constraint_row_is_rotational(row) ? 1.0 / body.inertia : 1.0 / body.mass + arm * arm / body.inertia;
      }
      inverse_effective_mass[static_cast<std::size_t>(model.constraint_offset(e) + row)] = inverse;
    }
  }
  (void)nq;
  const double rate = kPenaltyStepAngle / dt;
  for (int r = 0; r < m; ++r) {
    const auto row = static_cast<std::size_t>(r);
    const Element& owner = system_.constraint_owner(r);
    const bool rotational = system_.constraint_row_is_rotational(r);
    const double effective_mass = 1.0 / inverse_effective_mass[row];
    const auto& own = owner.penalty;
    const auto& global = settings_.penalty;
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

/// Refuses a step dt that needs more than max_steps steps to reach the model's t_end.
void check_step_count(const Model& model, double dt, long max_steps) {
  const double steps_needed = std::ceil(model.simulation.t_end / dt - 1e-9);  // [steps], a double: never overflows
  if (!(steps_needed <= static_cast<double>(max_steps))) {
    std::ostringstream msg;
    msg << SourceLocation{model.file, 0}.prefix() << "explicit Euler with dt = " << dt << " needs " << steps_needed
        << " steps to reach t_end = " << model.simulation.t_end << ", more than --max-steps " << max_steps
        << "; use a larger dt (above " << model.simulation.t_end / static_cast<double>(max_steps)
        << "), a shorter t_end, or raise --max-steps";
    throw InputError(msg.str());
  }
}

}  // namespace

EulerIntegrator::EulerIntegrator(const DaeSystem& system, EulerSettings settings)
    : system_(system), settings_(settings) {
  const Model& model = system.model();
  for (const Body& b : model.bodies())
    if (!(b.inertia > 0.0))
      throw InputError(b.where.prefix() + "body '" + b.name +
                       "' has zero inertia: explicit Euler needs every body's inertia to be positive "
                       "(use integrator: ida, or give the body an inertia)");
  const StartReport start = prepare_start(system, y0_, start_events_);
  assembly_correction_ = start.assembly.largest_position_change;
  settling_steps_ = start.equilibrium.steps;
  settling_displacement_ = start.equilibrium.largest_position_change;

  if (settings_.dt < 0.0 || !std::isfinite(settings_.dt)) throw InputError("dt must be a positive step (or 0 for automatic)");
  if (settings_.dt > 0.0) {
    dt_ = settings_.dt;
    check_step_count(model, dt_, settings_.max_steps);  // before penalties sized for a dt that cannot run
    penalty_ = make_penalty(dt_);
    stability_limit_ = estimate_stability_limit(system, y0_, &penalty_);
  } else {
    // Automatic: half the limit of the elements alone, then penalties for that step; shrink
    // once more if the penalties lowered the limit.
    const double physical_limit = estimate_stability_limit(system, y0_, nullptr);
    dt_ = std::isfinite(physical_limit) ? 0.5 * physical_limit : 1e-3 * model.simulation.t_end;
    for (int pass = 0; pass < 20; ++pass) {
      penalty_ = make_penalty(dt_);
      stability_limit_ = estimate_stability_limit(system, y0_, &penalty_);
      if (dt_ <= 0.8 * stability_limit_) break;
      dt_ = 0.5 * stability_limit_;
    }
  }
  if (dt_ > stability_limit_ && !settings_.force_dt) {
    std::ostringstream msg;
    msg << "the Euler step dt = " << dt_ << " is above the stability limit " << stability_limit_
        << " of this model (largest stable step, penalty joints included); use dt <= " << stability_limit_
        << " (e.g. --dt " << 0.5 * stability_limit_ << "), or --force-dt to run anyway";
    throw InputError(msg.str());
  }
  check_step_count(model, dt_, settings_.max_steps);
}

RunOutcome EulerIntegrator::run(double t_end, double output_interval, RunObserver& observer,
                                const std::atomic<bool>* stop) {
  const auto wall_start = std::chrono::steady_clock::now();
  RunOutcome outcome;
  outcome.stats.stability_limit = stability_limit_;
  outcome.stats.assembly_correction = assembly_correction_;
  outcome.stats.settling_steps = settling_steps_;
  outcome.stats.settling_displacement = settling_displacement_;
  outcome.stats.last_step = dt_;
  const int nq = system_.body_unknowns();
  const int m = system_.constraint_rows();
  const int nquad = system_.quadrature_count();
  std::vector<double> y = y0_;
  std::vector<double> force(static_cast<std::size_t>(nq)), rates(static_cast<std::size_t>(nquad));
  std::vector<double> quad(static_cast<std::size_t>(nquad), 0.0);
  std::vector<double> lambda(static_cast<std::size_t>(m), 0.0);
  std::vector<double> inverse_mass(static_cast<std::size_t>(nq));
  for (int k = 0; k < nq; ++k) inverse_mass[static_cast<std::size_t>(k)] = 1.0 / system_.mass_diagonal(k);
  double* q = y.data();
  double* v = y.data() + nq;
  // The multipliers stored in y (for output) are the penalty forces.
  double* y_lambda = y.data() + 2 * nq;

  // Modes as prepared (and settled) in the constructor; a second run starts from them too.
  system_.generalized_forces(0.0, q, v, force.data(), &penalty_, lambda.data());
  std::copy(lambda.begin(), lambda.end(), y_lambda);
  // Mode changes: the same root functions as IDA, checked at the end of every step (what
  // IITRAIN's "internal logic checks at each time step" did). A root that sits at zero right
  // after its commit is ignored until it leaves zero.
  const int root_count = system_.root_count();
  std::vector<double> g_before(static_cast<std::size_t>(root_count)), g_after(g_before.size());
  std::vector<int> direction(g_before.size(), 0);
  std::vector<EventRecord> events;
  outcome.events = start_events_;
  for (const EventRecord& record : start_events_) observer.event(record, y.data());
  outcome.stats.events += static_cast<long>(start_events_.size());
  if (root_count > 0) {
    // A state that starts exactly on a mode boundary and moves out of the mode (same rule as IDA's restart).
    std::vector<double> yp(y.size(), 0.0);
    for (int k = 0; k < nq; ++k) {
      yp[static_cast<std::size_t>(k)] = v[k];
      yp[static_cast<std::size_t>(nq + k)] = force[static_cast<std::size_t>(k)] * inverse_mass[static_cast<std::size_t>(k)];
    }
    if (system_.commit_boundary_roots(0.0, y.data(), yp.data(), events)) {
      for (const EventRecord& record : events) observer.event(record, y.data());
      outcome.events.insert(outcome.events.end(), events.begin(), events.end());
      outcome.stats.events += static_cast<long>(events.size());
    }
    system_.roots(0.0, y.data(), g_before.data());
  }
  outcome.initial_energy = system_.energy(y.data(), quad.data(), &penalty_);
  observer.sample(0.0, y.data(), y_lambda, quad.data());
  outcome.max_constraint_residual = system_.constraint_residual(q);

  // The loop runs on time: step k ends at k dt (no drift), the last one at t_end exactly; the
  // step count is bounded by max_steps, so it never overflows.
  long output_index = 1;
  double t = 0.0;
  long step = 0;
  while (t < t_end) {
    if (stop && stop->load()) {
      outcome.message = "interrupted at t = " + std::to_string(t);
      break;
    }
    if (step >= settings_.max_steps) {
      std::ostringstream msg;
      msg << "stopped at t = " << t << " after --max-steps " << settings_.max_steps << " steps of dt = " << dt_
          << ", before t_end = " << t_end << "; use a larger dt or raise --max-steps";
      outcome.message = msg.str();
      break;
    }
    ++step;
    const bool last = static_cast<double>(step) >= t_end / dt_ - 1e-9;
    const double t_next = last ? t_end : static_cast<double>(step) * dt_;
    const double h = t_next - t;
    system_.generalized_forces(t, q, v, force.data(), &penalty_, lambda.data());
    system_.quadrature_rates(t, y.data(), rates.data(), lambda.data());
    for (int k = 0; k < nquad; ++k) quad[static_cast<std::size_t>(k)] += h * rates[static_cast<std::size_t>(k)];
    for (int k = 0; k < nq; ++k) {
      v[k] += h * force[static_cast<std::size_t>(k)] * inverse_mass[static_cast<std::size_t>(k)];
      q[k] += h * v[k];
    }
    t = t_next;
    ++outcome.stats.steps;
    outcome.stats.residual_evaluations += 1;
    if (root_count > 0) {
      std::copy(lambda.begin(), lambda.end(), y_lambda);
      system_.roots(t, y.data(), g_after.data());
      bool fired = false;
      for (std::size_t k = 0; k < g_after.size(); ++k) {
        const double before = g_before[k], after = g_after[k];
        // Roots are positive inside their mode (element.hpp): a fall from >= 0 to < 0 leaves it.
        direction[k] = (before >= 0.0 && after < 0.0) ? -1 : (before < 0.0 && after >= 0.0) ? 1 : 0;
        fired = fired || direction[k] != 0;
      }
      if (fired) {
        events.clear();
        if (system_.commit_roots(t, y.data(), direction.data(), events)) {
          ++outcome.stats.reinitializations;
          system_.roots(t, y.data(), g_after.data());
        }
        for (const EventRecord& record : events) observer.event(record, y.data());
        outcome.events.insert(outcome.events.end(), events.begin(), events.end());
        outcome.stats.events += static_cast<long>(events.size());
      }
      std::swap(g_before, g_after);
    }
    bool finite = true;
    for (int k = 0; k < 2 * nq; ++k) finite = finite && std::isfinite(y[static_cast<std::size_t>(k)]);
    if (!finite) {
      std::ostringstream msg;
      msg << "explicit Euler diverged at t = " << t << " (a coordinate became infinite or NaN); the step "
          << dt_ << " is too large for the model as it deforms (stability limit at the start: " << stability_limit_ << ")";
      outcome.message = msg.str();
      break;
    }
    if (t >= std::min(t_end, static_cast<double>(output_index) * output_interval) * (1.0 - 1e-12) || last) {
      std::copy(lambda.begin(), lambda.end(), y_lambda);
      observer.sample(t, y.data(), y_lambda, quad.data());
      outcome.max_constraint_residual = std::max(outcome.max_constraint_residual, system_.constraint_residual(q));
      while (static_cast<double>(output_index) * output_interval <= t * (1.0 + 1e-12)) ++output_index;
    }
  }
  outcome.ok = outcome.message.empty() && t >= t_end;  // a run that did not reach t_end is never ok
  outcome.t_reached = t;
  outcome.y = y;
  outcome.quadratures = quad;
  outcome.final_energy = system_.energy(y.data(), quad.data(), &penalty_);
  outcome.stats.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return outcome;
}

}  // namespace railcrash
