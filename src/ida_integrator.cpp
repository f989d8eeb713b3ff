#include "railcrash/ida_integrator.hpp"

#include <idas/idas.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_klu.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <sstream>

#include "railcrash/initial_conditions.hpp"

namespace railcrash {

namespace {

std::string flag_name(int flag) {
  char* name = IDAGetReturnFlagName(flag);
  std::string out = name ? name : std::to_string(flag);
  std::free(name);
  return out;
}

/// Consistent rates at a (re)start, after committing the roots that sit exactly on a mode
/// boundary and are about to leave it (IDA would leave them inactive).
void restart_state(const DaeSystem& system, double t, std::vector<double>& y, std::vector<double>& yp,
                   std::vector<EventRecord>& events) {
  consistent_rates(system, t, y, yp);
  for (int pass = 0; pass < 10 && system.commit_boundary_roots(t, y.data(), yp.data(), events); ++pass)
    consistent_rates(system, t, y, yp);
}

/// SUNLinSol_KLU's initialize (called by IDA at the first solve after every IDAInit or
/// IDAReInit) discards the symbolic analysis, so each restart would redo the ordering of a
/// matrix whose pattern never changes. This replacement keeps a symbolic analysis once made;
/// the next setup then refactors numerically (with the library's own fall-back to a full
/// factorization when the pivots degrade).
int klu_initialize_keeping_symbolic(SUNLinearSolver solver) {
  auto* content = static_cast<SUNLinearSolverContent_KLU>(solver->content);
  content->first_factorize = content->symbolic == nullptr ? 1 : 0;
  content->last_flag = SUNLS_SUCCESS;
  return SUNLS_SUCCESS;
}

/// SUNLinSol_KLU's setup refactors with the previous pivot order, then, when KLU's cheap
/// reciprocal condition estimate is below eps^(2/3), computes the expensive condition
/// estimate and, when that is large too, factors afresh. The GGL Jacobian of a crash model
/// mixes masses, inertias and multiplier rows over many decades, so its condition estimate
/// is always "large": every setup paid for three factorizations' worth of work (measured:
/// klu_condest and a full klu_factor at every Jacobian update). This setup keeps the pivot
/// order while it stays sound, judged by the pivot growth instead (KLU's reciprocal pivot
/// growth, cheap: one pass over the matrix), and factors afresh with partial pivoting when
/// the growth exceeds 1e8 or the refactorization fails.
int klu_setup_reusing_pivots(SUNLinearSolver solver, SUNMatrix matrix) {
  auto* content = static_cast<SUNLinearSolverContent_KLU>(solver->content);
  if (content->first_factorize || content->symbolic == nullptr || content->numeric == nullptr)
    return SUNLinSolSetup_KLU(solver, matrix);  // analysis and first factorization
  sunindextype* columns = SUNSparseMatrix_IndexPointers(matrix);
  sunindextype* rows = SUNSparseMatrix_IndexValues(matrix);
  double* values = SUNSparseMatrix_Data(matrix);
  constexpr double kSmallestReciprocalGrowth = 1e-8;
  if (klu_l_refactor(columns, rows, values, content->symbolic, content->numeric, &content->common) &&
      klu_l_rgrowth(columns, rows, values, content->symbolic, content->numeric, &content->common) &&
      content->common.rgrowth > kSmallestReciprocalGrowth) {
    content->last_flag = SUNLS_SUCCESS;
    return SUNLS_SUCCESS;
  }
  klu_l_free_numeric(&content->numeric, &content->common);
  content->numeric = klu_l_factor(columns, rows, values, content->symbolic, &content->common);
  if (content->numeric == nullptr) {
    content->last_flag = SUNLS_PACKAGE_FAIL_REC;  // singular: IDA cuts the step
    return SUNLS_PACKAGE_FAIL_REC;
  }
  content->last_flag = SUNLS_SUCCESS;
  return SUNLS_SUCCESS;
}

}  // namespace

/// Everything SUNDIALS owns for one run; destroyed in reverse order of creation.
struct IdaIntegrator::Impl {
  const DaeSystem& system;
  SUNContext context = nullptr;
  N_Vector y = nullptr, yp = nullptr, ids = nullptr, atol = nullptr, quad = nullptr, quad_atol = nullptr;
  N_Vector y_internal = nullptr;  // IDA's solution at its own time t_n
  SUNMatrix jacobian = nullptr;
  SUNLinearSolver linear_solver = nullptr;
  void* ida = nullptr;
  std::exception_ptr callback_error;
  std::string last_sundials_message;

  explicit Impl(const DaeSystem& s) : system(s) {}
  ~Impl() {
    if (ida) IDAFree(&ida);
    if (linear_solver) SUNLinSolFree(linear_solver);
    if (jacobian) SUNMatDestroy(jacobian);
    for (N_Vector* v : {&y, &yp, &ids, &atol, &quad, &quad_atol, &y_internal})
      if (*v) N_VDestroy(*v);
    if (context) SUNContext_Free(&context);
  }

  void check(int flag, const char* function) const {
    if (flag >= 0) return;
    std::ostringstream msg;
    msg << function << " failed with " << flag_name(flag);
    if (!last_sundials_message.empty()) msg << ": " << last_sundials_message;
    throw SolverError(msg.str());
  }
  template <class P>
  P* created(P* pointer, const char* function) const {
    if (!pointer) throw SolverError(std::string(function) + " could not allocate");
    return pointer;
  }

  static int residual(realtype t, N_Vector yy, N_Vector ypv, N_Vector rr, void* user) {
    auto* self = static_cast<Impl*>(user);
    try {
      self->system.residual(t, N_VGetArrayPointer(yy), N_VGetArrayPointer(ypv), N_VGetArrayPointer(rr));
      const double* r = N_VGetArrayPointer(rr);
      for (sunindextype k = 0; k < N_VGetLength(rr); ++k)
        if (!std::isfinite(r[k])) return 1;  // recoverable: IDA cuts the step
      return 0;
    } catch (...) {
      self->callback_error = std::current_exception();
      return -1;
    }
  }

  static int jacobian_values(realtype t, realtype cj, N_Vector yy, N_Vector ypv, N_Vector, SUNMatrix matrix, void* user,
                             N_Vector, N_Vector, N_Vector) {
    auto* self = static_cast<Impl*>(user);
    try {
      const SparsePattern& p = self->system.pattern();
      // SUNMatZero also clears the index arrays of a sparse matrix: write them every time.
      sunindextype* columns = SUNSparseMatrix_IndexPointers(matrix);
      sunindextype* rows = SUNSparseMatrix_IndexValues(matrix);
      for (std::size_t k = 0; k < p.column_start.size(); ++k) columns[k] = p.column_start[k];
      for (std::size_t k = 0; k < p.row_index.size(); ++k) rows[k] = p.row_index[k];
      self->system.jacobian(t, cj, N_VGetArrayPointer(yy), N_VGetArrayPointer(ypv), SUNSparseMatrix_Data(matrix));
      return 0;
    } catch (...) {
      self->callback_error = std::current_exception();
      return -1;
    }
  }

  static int quadrature(realtype t, N_Vector yy, N_Vector, N_Vector rates, void* user) {
    auto* self = static_cast<Impl*>(user);
    try {
      self->system.quadrature_rates(t, N_VGetArrayPointer(yy), N_VGetArrayPointer(rates));
      return 0;
    } catch (...) {
      self->callback_error = std::current_exception();
      return -1;
    }
  }

  static int root_functions(realtype t, N_Vector yy, N_Vector, realtype* g, void* user) {
    auto* self = static_cast<Impl*>(user);
    try {
      self->system.roots(t, N_VGetArrayPointer(yy), g);
      return 0;
    } catch (...) {
      self->callback_error = std::current_exception();
      return -1;
    }
  }

  /// Adds IDA's counters to stats (they restart at every IDAReInit).
  void accumulate(RunStatistics& stats) const {
    long value = 0;
    check(IDAGetNumSteps(ida, &value), "IDAGetNumSteps");
    stats.steps += value;
    check(IDAGetNumResEvals(ida, &value), "IDAGetNumResEvals");
    stats.residual_evaluations += value;
    check(IDAGetNumJacEvals(ida, &value), "IDAGetNumJacEvals");
    stats.jacobian_evaluations += value;
    check(IDAGetNumNonlinSolvIters(ida, &value), "IDAGetNumNonlinSolvIters");
    stats.nonlinear_iterations += value;
    check(IDAGetNumErrTestFails(ida, &value), "IDAGetNumErrTestFails");
    stats.error_test_failures += value;
    check(IDAGetNumNonlinSolvConvFails(ida, &value), "IDAGetNumNonlinSolvConvFails");
    stats.nonlinear_convergence_failures += value;
    realtype step = 0.0;
    check(IDAGetLastStep(ida, &step), "IDAGetLastStep");
    if (step > 0.0) stats.last_step = step;
  }

  static void error_handler(int, const char* module, const char* function, char* message, void* user) {
    auto* self = static_cast<Impl*>(user);
    self->last_sundials_message = std::string(module) + "/" + function + ": " + message;
  }

  void rethrow_callback_error() {
    if (callback_error) {
      std::exception_ptr e = callback_error;
      callback_error = nullptr;
      std::rethrow_exception(e);
    }
  }
};

IdaIntegrator::IdaIntegrator(const DaeSystem& system, IdaSettings settings) : system_(system), settings_(settings) {
  if (!(settings_.rtol > 0.0) || !std::isfinite(settings_.rtol))
    throw InputError("rtol must be a positive number (typical: 1e-6)");
}

IdaIntegrator::~IdaIntegrator() = default;

RunOutcome IdaIntegrator::run(double t_end, double output_interval, RunObserver& observer,
                              const std::atomic<bool>* stop) {
  const auto wall_start = std::chrono::steady_clock::now();
  RunOutcome outcome;
  Impl impl(system_);
  const int n = system_.size();
  const int nq = system_.body_unknowns();
  const int m = system_.constraint_rows();
  const int nquad = system_.quadrature_count();
  const Model& model = system_.model();

  // ---- consistent positions and velocities ----
  std::vector<double> y0;
  std::vector<EventRecord> settling_events;
  const StartReport start = prepare_start(system_, y0, settling_events);
  outcome.stats.assembly_correction = start.assembly.largest_position_change;
  outcome.stats.settling_steps = start.equilibrium.steps;
  outcome.stats.settling_displacement = start.equilibrium.largest_position_change;

  // ---- scales for the tolerances ----
  const double length = model.length_scale();
  std::vector<double> f0(static_cast<std::size_t>(nq), 0.0);
  system_.generalized_forces(0.0, y0.data(), y0.data() + nq, f0.data());
  double force_scale = 0.0, speed = 0.0, total_mass = 0.0;
  for (int i = 0; i < model.body_count(); ++i) {
    force_scale = std::max({force_scale, std::abs(f0[static_cast<std::size_t>(3 * i)]),
                            std::abs(f0[static_cast<std::size_t>(3 * i + 1)]),
                            std::abs(f0[static_cast<std::size_t>(3 * i + 2)]) / length});
    speed = std::max({speed, std::abs(y0[static_cast<std::size_t>(nq + 3 * i)]),
                      std::abs(y0[static_cast<std::size_t>(nq + 3 * i + 1)]),
                      std::abs(y0[static_cast<std::size_t>(nq + 3 * i + 2)]) * length});
    total_mass += model.bodies()[static_cast<std::size_t>(i)].mass;
  }
  double energy_scale = std::max(system_.kinetic_energy(y0.data() + nq), force_scale * length);
  // A model at rest with no load still needs positive tolerances.
  if (!(energy_scale > 0.0)) energy_scale = total_mass * (length / t_end) * (length / t_end);
  speed = std::max(speed, std::sqrt(2.0 * energy_scale / total_mass));
  if (!(speed > 0.0)) speed = length / t_end;
  if (!(force_scale > 0.0)) force_scale = total_mass * speed * speed / length;
  const double rtol = settings_.rtol;
  const double atol_length = settings_.atol ? *settings_.atol : 0.1 * rtol * length;
  const double atol_speed = atol_length * speed / length;
  // Multipliers stay out of the error test (IDASetSuppressAlg); their weights only enter the
  // Newton convergence test, where index-2 unknowns carry round-off amplified by 1/h. Weights
  // as tight as the differential ones make that test fail at small steps (seen on the
  // slider-crank at rtol <= 1e-8), so lambda gets 100 rtol F and mu (zero on the exact
  // solution) the speed scale V.
  const double atol_force = std::min(1.0, 100.0 * rtol) * force_scale;

  try {
    impl.check(SUNContext_Create(nullptr, &impl.context), "SUNContext_Create");
    impl.y = impl.created(N_VNew_Serial(n, impl.context), "N_VNew_Serial");
    impl.yp = impl.created(N_VClone(impl.y), "N_VClone");
    impl.ids = impl.created(N_VClone(impl.y), "N_VClone");
    impl.atol = impl.created(N_VClone(impl.y), "N_VClone");
    impl.quad = impl.created(N_VNew_Serial(nquad, impl.context), "N_VNew_Serial");
    impl.quad_atol = impl.created(N_VClone(impl.quad), "N_VClone");

    double* y = N_VGetArrayPointer(impl.y);
    double* yp = N_VGetArrayPointer(impl.yp);
    std::vector<double> yp0;
    std::vector<EventRecord> start_events = settling_events;
    restart_state(system_, 0.0, y0, yp0, start_events);
    std::copy(y0.begin(), y0.end(), y);
    std::copy(yp0.begin(), yp0.end(), yp);
    const std::vector<double> ids = system_.differential_ids();
    std::copy(ids.begin(), ids.end(), N_VGetArrayPointer(impl.ids));
    double* atol = N_VGetArrayPointer(impl.atol);
    for (int i = 0; i < model.body_count(); ++i) {
      atol[3 * i] = atol[3 * i + 1] = atol_length;
      atol[3 * i + 2] = atol_length / length;
      atol[nq + 3 * i] = atol[nq + 3 * i + 1] = atol_speed;
      atol[nq + 3 * i + 2] = atol_speed / length;
    }
    for (int r = 0; r < m; ++r) {
      atol[2 * nq + r] = atol_force;
      atol[2 * nq + m + r] = speed;
    }
    N_VConst(0.0, impl.quad);
    double* quad_atol = N_VGetArrayPointer(impl.quad_atol);
    for (int k = 0; k < nquad; ++k) quad_atol[k] = 0.1 * rtol * energy_scale;
    quad_atol[DaeSystem::kKineticIntegral] *= t_end;

    impl.ida = impl.created(IDACreate(impl.context), "IDACreate");
    impl.check(IDASetErrHandlerFn(impl.ida, &Impl::error_handler, &impl), "IDASetErrHandlerFn");
    impl.check(IDAInit(impl.ida, &Impl::residual, 0.0, impl.y, impl.yp), "IDAInit");
    impl.check(IDASetUserData(impl.ida, &impl), "IDASetUserData");
    impl.check(IDASVtolerances(impl.ida, rtol, impl.atol), "IDASVtolerances");
    impl.check(IDASetId(impl.ida, impl.ids), "IDASetId");
    impl.check(IDASetSuppressAlg(impl.ida, SUNTRUE), "IDASetSuppressAlg");
    impl.check(IDASetMaxNumSteps(impl.ida, settings_.max_steps_per_output), "IDASetMaxNumSteps");
    impl.check(IDASetStopTime(impl.ida, t_end), "IDASetStopTime");
    const SparsePattern& pattern = system_.pattern();
    impl.jacobian = impl.created(SUNSparseMatrix(n, n, pattern.nonzeros(), CSC_MAT, impl.context), "SUNSparseMatrix");
    impl.linear_solver = impl.created(SUNLinSol_KLU(impl.y, impl.jacobian, impl.context), "SUNLinSol_KLU");
    impl.linear_solver->ops->initialize = &klu_initialize_keeping_symbolic;
    impl.linear_solver->ops->setup = &klu_setup_reusing_pivots;
    impl.check(IDASetLinearSolver(impl.ida, impl.linear_solver, impl.jacobian), "IDASetLinearSolver");
    impl.check(IDASetJacFn(impl.ida, &Impl::jacobian_values), "IDASetJacFn");
    impl.check(IDAQuadInit(impl.ida, &Impl::quadrature, impl.quad), "IDAQuadInit");
    impl.check(IDAQuadSVtolerances(impl.ida, rtol, impl.quad_atol), "IDAQuadSVtolerances");
    impl.check(IDASetQuadErrCon(impl.ida, SUNTRUE), "IDASetQuadErrCon");
    const int root_count = system_.root_count();
    std::vector<int> root_info(static_cast<std::size_t>(root_count), 0);
    std::vector<EventRecord> events;
    if (root_count > 0) {
      impl.check(IDARootInit(impl.ida, root_count, &Impl::root_functions), "IDARootInit");
      impl.check(IDASetNoInactiveRootWarn(impl.ida), "IDASetNoInactiveRootWarn");
    }

    // The lag test of a mode change without restart, from the elements that changed alone
    // (so an event costs the same in a 2-car and in a 200-car model): over [t_root, t_n] IDA
    // used their old law; the velocity error that made is about |change of their forces| / M
    // (t_n - t_root) on their bodies (trapezoid between t_root and t_n: a kink, continuous at
    // t_root, counts half), the error of their work quadratures |change of their power|
    // (t_n - t_root); both must stay within the local tolerances. A constraint element that
    // changed (a joint failed) always restarts: its equations changed.
    impl.y_internal = impl.created(N_VClone(impl.y), "N_VClone");
    std::vector<double> force_change(static_cast<std::size_t>(nq), 0.0);  // [force] per body unknown
    std::vector<int> touched;                                             // entries of force_change in use
    std::vector<int> candidates, changed_elements;
    std::vector<std::array<DaeSystem::ElementLoad, 2>> loads_before;      // per candidate: at t_root, at t_n
    const auto lag_within_tolerance = [&](const double* y_root, const double* y_n, double t_root, double t_n,
                                          const double* quadratures) {
      const double lag = t_n - t_root;
      bool within = true;
      for (const int e : changed_elements) {
        if (system_.model().elements()[static_cast<std::size_t>(e)]->constraint_count() > 0 &&
            system_.model().elements()[static_cast<std::size_t>(e)]->failed()) {
          within = false;
          break;
        }
        const auto where = std::find(candidates.begin(), candidates.end(), e);
        if (where == candidates.end()) {  // changed without a root of its own firing: no "before"
          within = false;
          break;
        }
        const auto& before = loads_before[static_cast<std::size_t>(where - candidates.begin())];
        const DaeSystem::ElementLoad after_root = system_.element_load(e, t_root, y_root);
        const DaeSystem::ElementLoad after_n = system_.element_load(e, t_n, y_n);
        const int work = DaeSystem::kFirstElementWork + e;
        const double power_change =
            0.5 * (std::abs(after_root.power - before[0].power) + std::abs(after_n.power - before[1].power));
        if (power_change * lag > rtol * std::abs(quadratures[work]) + quad_atol[work]) within = false;
        for (std::size_t slot = 0; slot < 2; ++slot) {
          const int b = after_root.body[slot];
          if (b == kGround) continue;
          const auto change = [&](const Pose<double>& root_new, const Pose<double>& root_old, const Pose<double>& n_new,
                                  const Pose<double>& n_old, double Pose<double>::*c) {
            return 0.5 * (std::abs(root_new.*c - root_old.*c) + std::abs(n_new.*c - n_old.*c));
          };
          const double changes[3] = {
              change(after_root.force[slot], before[0].force[slot], after_n.force[slot], before[1].force[slot], &Pose<double>::x),
              change(after_root.force[slot], before[0].force[slot], after_n.force[slot], before[1].force[slot], &Pose<double>::y),
              change(after_root.force[slot], before[0].force[slot], after_n.force[slot], before[1].force[slot],
                     &Pose<double>::theta)};
          for (int c = 0; c < 3; ++c) {
            if (changes[c] == 0.0) continue;
            const int k = 3 * b + c;
            if (force_change[static_cast<std::size_t>(k)] == 0.0) touched.push_back(k);
            force_change[static_cast<std::size_t>(k)] += changes[c];
          }
        }
      }
      for (const int k : touched) {
        const double mass = system_.mass_diagonal(k);
        const double velocity_error = force_change[static_cast<std::size_t>(k)] / mass * lag;
        // A zero-inertia rotation (mass 0) has no estimate: restart.
        if (!(mass > 0.0) || velocity_error > rtol * std::abs(y_n[nq + k]) + atol[nq + k]) within = false;
        force_change[static_cast<std::size_t>(k)] = 0.0;
      }
      touched.clear();
      return within;
    };

    const double* lambda = y + 2 * nq;
    std::vector<double> quad_now(static_cast<std::size_t>(nquad), 0.0);
    outcome.initial_energy = system_.energy(y, quad_now.data());
    for (const EventRecord& record : start_events) observer.event(record, y);
    outcome.events = start_events;
    outcome.stats.events += static_cast<long>(start_events.size());
    observer.sample(0.0, y, lambda, quad_now.data());
    outcome.max_constraint_residual = system_.constraint_residual(y);

    bool continued_after_root = false;  // the last return was a root IDA went on from
    std::vector<double> y_at_root;      // the state there
    long output_index = 1;
    double t_reached = 0.0;
    while (t_reached < t_end) {
      if (stop && stop->load()) {
        outcome.message = "interrupted at t = " + std::to_string(t_reached);
        break;
      }
      const double t_out = std::min(t_end, static_cast<double>(output_index) * output_interval);
      double t_return = t_reached;
      impl.last_sundials_message.clear();
      const int flag = IDASolve(impl.ida, t_out, &t_return, impl.y, impl.yp, IDA_NORMAL);
      impl.rethrow_callback_error();
      if (flag == IDA_ILL_INPUT && continued_after_root &&
          impl.last_sundials_message.find("very near") != std::string::npos) {
        // A root of the new modes sits at zero and stays there (a body resting exactly on
        // a kink): IDA refuses to go on from the root return. Restart there instead; at a
        // restart IDA leaves such a root inactive until it moves.
        continued_after_root = false;
        std::copy(y_at_root.begin(), y_at_root.end(), y);
        std::vector<double> yp_now;
        std::vector<EventRecord> restart_events;
        restart_state(system_, t_reached, y_at_root, yp_now, restart_events);
        for (const EventRecord& record : restart_events) observer.event(record, y);
        outcome.events.insert(outcome.events.end(), restart_events.begin(), restart_events.end());
        outcome.stats.events += static_cast<long>(restart_events.size());
        std::copy(y_at_root.begin(), y_at_root.end(), y);
        std::copy(yp_now.begin(), yp_now.end(), yp);
        impl.accumulate(outcome.stats);
        impl.check(IDAReInit(impl.ida, t_reached, impl.y, impl.yp), "IDAReInit");
        impl.check(IDAQuadReInit(impl.ida, impl.quad), "IDAQuadReInit");
        ++outcome.stats.reinitializations;
        continue;
      }
      continued_after_root = false;
      if (flag < 0) {
        t_reached = t_return;
        std::ostringstream msg;
        msg << "IDA failed at t = " << t_return << " with " << flag_name(flag);
        if (!impl.last_sundials_message.empty()) msg << " (" << impl.last_sundials_message << ")";
        outcome.message = msg.str();
        break;
      }
      impl.check(IDAGetQuad(impl.ida, &t_return, impl.quad), "IDAGetQuad");
      t_reached = t_return;
      const double* quad = N_VGetArrayPointer(impl.quad);
      if (flag == IDA_ROOT_RETURN) {
        // A mode change. IDA's own solution is already at t_n >= t_root, computed with the
        // old law over [t_root, t_n]. When the new law agrees with the old one there within
        // the local tolerance (a kink: a stiffness changes, the force does not jump), IDA
        // simply goes on, as over any non-smooth right-hand side: no restart, so an event in
        // one car of a long train does not reset the step size of the whole train. A jump
        // (rupture, joint failure, preload) or a root left exactly at zero (IDA would stop on
        // it) restarts from consistent values at t_root instead.
        impl.check(IDAGetRootInfo(impl.ida, root_info.data()), "IDAGetRootInfo");
        ++outcome.stats.root_returns;
        realtype t_internal = t_reached;
        impl.check(IDAGetCurrentTime(impl.ida, &t_internal), "IDAGetCurrentTime");
        impl.check(IDAGetDky(impl.ida, t_internal, 0, impl.y_internal), "IDAGetDky");
        const double* y_internal = N_VGetArrayPointer(impl.y_internal);
        candidates = system_.elements_of_roots(root_info.data());
        loads_before.resize(candidates.size());
        for (std::size_t c = 0; c < candidates.size(); ++c)
          loads_before[c] = {system_.element_load(candidates[c], t_reached, y),
                             system_.element_load(candidates[c], t_internal, y_internal)};
        events.clear();
        changed_elements.clear();
        const bool changed = system_.commit_roots(t_reached, y, root_info.data(), events, &changed_elements);
        const bool restart = changed && !lag_within_tolerance(y, y_internal, t_reached, t_internal, quad);
        std::vector<double> y_now(y, y + n), yp_now;
        if (restart && changed) restart_state(system_, t_reached, y_now, yp_now, events);
        for (const EventRecord& record : events) observer.event(record, y);
        outcome.events.insert(outcome.events.end(), events.begin(), events.end());
        outcome.stats.events += static_cast<long>(events.size());
        continued_after_root = !restart;
        if (!restart) y_at_root.assign(y, y + n);
        if (restart) {
          if (changed) {
            std::copy(y_now.begin(), y_now.end(), y);
            std::copy(yp_now.begin(), yp_now.end(), yp);
          }
          // At a restart IDA leaves a root that is exactly zero inactive until it moves.
          impl.accumulate(outcome.stats);
          impl.check(IDAReInit(impl.ida, t_reached, impl.y, impl.yp), "IDAReInit");
          impl.check(IDAQuadReInit(impl.ida, impl.quad), "IDAQuadReInit");
          ++outcome.stats.reinitializations;
        }
        if (t_reached < t_out * (1.0 - 1e-14)) continue;
      }
      observer.sample(t_reached, y, lambda, quad);
      outcome.max_constraint_residual = std::max(outcome.max_constraint_residual, system_.constraint_residual(y));
      if (t_reached >= t_out * (1.0 - 1e-14)) ++output_index;
    }
    outcome.ok = outcome.message.empty();
    outcome.t_reached = t_reached;
    outcome.y.assign(y, y + n);
    const double* quad = N_VGetArrayPointer(impl.quad);
    outcome.quadratures.assign(quad, quad + nquad);
    outcome.final_energy = system_.energy(y, quad);

    impl.accumulate(outcome.stats);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    outcome.ok = false;
    outcome.message = e.what();
  }
  outcome.stats.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return outcome;
}

double max_abs(const std::vector<double>& values) {
  double worst = 0.0;
  for (double v : values) worst = std::max(worst, std::abs(v));
  return worst;
}

}  // namespace railcrash
