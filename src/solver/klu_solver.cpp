#include "klu_solver.hpp"

#include <klu.h>
#include <nvector/nvector_serial.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <algorithm>
#include <string>

#include "railcrash/solver/integrator.hpp"

namespace railcrash {

namespace {

/// The solver's state, SUNLinearSolver::content.
struct KluContent {
  klu_common common;                // KLU's settings and statistics
  klu_symbolic* symbolic = nullptr;  // ordering and block triangular form, kept between restarts
  klu_numeric* numeric = nullptr;    // the last factorization
  bool first_factorize = true;       // the next setup analyses and factors afresh
  bool check_growth = false;         // the next refactorization's pivot growth is checked
  std::vector<int> orderings;        // the fill-reducing orderings the first analysis tries: 0 AMD, 1 COLAMD
  int ordering = -1;                 // the one kept (-1: none yet)
  int size = 0;                      // rows and columns
  std::vector<int> column_start;     // the matrix's pattern (CSC), 32-bit
  std::vector<int> row_index;
  PhaseClock* clock = nullptr;
  int last_flag = SUNLS_SUCCESS;
};

KluContent& content_of(SUNLinearSolver solver) { return *static_cast<KluContent*>(solver->content); }

SUNLinearSolver_Type klu_type(SUNLinearSolver) { return SUNLINEARSOLVER_DIRECT; }

SUNLinearSolver_ID klu_id(SUNLinearSolver) { return SUNLINEARSOLVER_CUSTOM; }

/// Called by IDA at the first solve after every IDAInit or IDAReInit. A symbolic analysis once
/// made is kept (the pattern never changes); the next setup then refactors numerically, with
/// the fall-back to a full factorization below.
int klu_initialize(SUNLinearSolver solver) {
  KluContent& klu = content_of(solver);
  klu.first_factorize = klu.symbolic == nullptr;
  klu.last_flag = SUNLS_SUCCESS;
  return klu.last_flag;
}

/// A failed KLU call's flag for IDA: a singular matrix is recoverable (IDA cuts its step); no
/// memory, or factors past 32-bit indices, are not (IDA stops with IDA_LSETUP_FAIL and
/// klu_failure says why).
int failure_flag(const KluContent& klu) {
  return klu.common.status == KLU_SINGULAR ? SUNLS_PACKAGE_FAIL_REC : SUNLS_PACKAGE_FAIL_UNREC;
}

/// The entries KLU stores for a factorization: L, U and the off-diagonal blocks.
long entries_of(const klu_numeric* numeric) {
  return static_cast<long>(numeric->lnz) + numeric->unz + numeric->nzoff;
}

/// The first analysis: each of the solver's fill-reducing orderings (by default both of KLU's,
/// AMD on A + A^T and COLAMD on A^T A), each followed by a factorization with partial pivoting
/// of the first matrix; the one whose factors hold fewer entries is kept (a tie keeps the first
/// tried, AMD), with its factorization. Every later refactorization and solve streams through
/// those entries, and the pattern never changes, so this is decided once per run. (The Jacobians of the crash models are structurally almost
/// symmetric, where AMD is the natural choice: 6,832 entries against COLAMD's 9,634 on
/// mu_3plus3_si, 2,306 against 2,751 on the report's two-car crash; bench/HISTORY.md, "KLU's
/// ordering chosen by fill".)
int analyse_and_factor_first(KluContent& klu, double* values) {
  int failure = SUNLS_PACKAGE_FAIL_UNREC;
  int failed_status = KLU_OK;
  for (const int ordering : klu.orderings) {
    klu.common.ordering = ordering;
    klu_symbolic* symbolic = klu_analyze(klu.size, klu.column_start.data(), klu.row_index.data(), &klu.common);
    if (symbolic == nullptr) continue;
    klu_numeric* numeric = klu_factor(klu.column_start.data(), klu.row_index.data(), values, symbolic, &klu.common);
    if (numeric == nullptr) {
      failure = failure_flag(klu);
      failed_status = klu.common.status;
      klu_free_symbolic(&symbolic, &klu.common);
      continue;
    }
    if (klu.numeric == nullptr || entries_of(numeric) < entries_of(klu.numeric)) {
      if (klu.numeric != nullptr) klu_free_numeric(&klu.numeric, &klu.common);
      if (klu.symbolic != nullptr) klu_free_symbolic(&klu.symbolic, &klu.common);
      klu.symbolic = symbolic;
      klu.numeric = numeric;
      klu.ordering = ordering;
    } else {
      klu_free_numeric(&numeric, &klu.common);
      klu_free_symbolic(&symbolic, &klu.common);
    }
  }
  if (klu.numeric == nullptr) {
    klu.common.status = failed_status;
    return failure;
  }
  klu.common.ordering = klu.ordering;
  klu.common.status = KLU_OK;
  return SUNLS_SUCCESS;
}

/// A factorization with partial pivoting, from scratch; the first one also analyses
/// (analyse_and_factor_first).
int analyse_and_factor(KluContent& klu, double* values) {
  if (klu.symbolic == nullptr) return analyse_and_factor_first(klu, values);
  if (klu.numeric != nullptr) klu_free_numeric(&klu.numeric, &klu.common);
  klu.numeric = klu_factor(klu.column_start.data(), klu.row_index.data(), values, klu.symbolic, &klu.common);
  return klu.numeric == nullptr ? failure_flag(klu) : SUNLS_SUCCESS;
}

/// Refactors with the previous pivot order; factors afresh when the refactorization fails
/// (a zero pivot) or, when asked for (klu_check_pivot_growth_at_next_setup), when KLU's
/// reciprocal pivot growth (one pass over the matrix and U) has fallen below 1e-8.
int klu_setup(SUNLinearSolver solver, SUNMatrix matrix) {
  KluContent& klu = content_of(solver);
  const PhaseClock::Scope timed(klu.clock, Phase::LinearSetup);
  double* values = SUNSparseMatrix_Data(matrix);
  const bool check_growth = klu.check_growth;
  klu.check_growth = false;
  if (klu.first_factorize || klu.numeric == nullptr) {
    klu.last_flag = analyse_and_factor(klu, values);
    klu.first_factorize = klu.last_flag != SUNLS_SUCCESS;
    return klu.last_flag;
  }
  constexpr double kSmallestReciprocalGrowth = 1e-8;
  if (klu_refactor(klu.column_start.data(), klu.row_index.data(), values, klu.symbolic, klu.numeric, &klu.common) &&
      (!check_growth ||
       (klu_rgrowth(klu.column_start.data(), klu.row_index.data(), values, klu.symbolic, klu.numeric, &klu.common) &&
        klu.common.rgrowth > kSmallestReciprocalGrowth))) {
    klu.last_flag = SUNLS_SUCCESS;
    return klu.last_flag;
  }
  klu.last_flag = analyse_and_factor(klu, values);
  return klu.last_flag;
}

/// x = A^-1 b with the last factorization.
int klu_solve_vector(SUNLinearSolver solver, SUNMatrix, N_Vector x, N_Vector b, realtype) {
  KluContent& klu = content_of(solver);
  const PhaseClock::Scope timed(klu.clock, Phase::LinearSolve);
  const double* from = N_VGetArrayPointer(b);
  double* to = N_VGetArrayPointer(x);
  if (to != from) std::copy(from, from + klu.size, to);
  klu.last_flag = klu_solve(klu.symbolic, klu.numeric, klu.size, 1, to, &klu.common) ? SUNLS_SUCCESS : failure_flag(klu);
  return klu.last_flag;
}

sunindextype klu_last_flag(SUNLinearSolver solver) { return content_of(solver).last_flag; }

int klu_free(SUNLinearSolver solver) {
  if (solver == nullptr) return SUNLS_SUCCESS;
  if (solver->content != nullptr) {
    KluContent* klu = &content_of(solver);
    if (klu->numeric != nullptr) klu_free_numeric(&klu->numeric, &klu->common);
    if (klu->symbolic != nullptr) klu_free_symbolic(&klu->symbolic, &klu->common);
    delete klu;
    solver->content = nullptr;
  }
  SUNLinSolFreeEmpty(solver);
  return SUNLS_SUCCESS;
}

/// IDA zeroes its Jacobian matrix before each evaluation; SUNDIALS' sparse zero clears the
/// index arrays too. The Jacobian function here overwrites every value and the pattern is fixed.
int keep_matrix(SUNMatrix) { return 0; }

}  // namespace

SUNLinearSolver make_klu_solver(SUNContext context, const std::vector<int>& column_start, const std::vector<int>& row_index,
                                PhaseClock* clock, KluOrdering ordering) {
  SUNLinearSolver solver = SUNLinSolNewEmpty(context);
  if (solver == nullptr) return nullptr;
  auto* klu = new KluContent;
  klu_defaults(&klu->common);
  // The ordering is chosen at the first analysis (analyse_and_factor_first) from these.
  switch (ordering) {
    case KluOrdering::FewestEntries: klu->orderings = {0, 1}; break;
    case KluOrdering::Amd: klu->orderings = {0}; break;
    case KluOrdering::Colamd: klu->orderings = {1}; break;
  }
  klu->size = static_cast<int>(column_start.size()) - 1;
  klu->column_start = column_start;
  klu->row_index = row_index;
  klu->clock = clock;
  solver->content = klu;
  solver->ops->gettype = &klu_type;
  solver->ops->getid = &klu_id;
  solver->ops->initialize = &klu_initialize;
  solver->ops->setup = &klu_setup;
  solver->ops->solve = &klu_solve_vector;
  solver->ops->lastflag = &klu_last_flag;
  solver->ops->free = &klu_free;
  return solver;
}

void klu_check_pivot_growth_at_next_setup(SUNLinearSolver solver) { content_of(solver).check_growth = true; }

long klu_factor_entries(SUNLinearSolver solver) {
  const klu_numeric* numeric = content_of(solver).numeric;
  return numeric == nullptr ? 0 : entries_of(numeric);
}

std::string klu_ordering(SUNLinearSolver solver) {
  switch (content_of(solver).ordering) {
    case 0: return "AMD";
    case 1: return "COLAMD";
    default: return "";
  }
}

std::string klu_failure(SUNLinearSolver solver) {
  const KluContent& klu = content_of(solver);
  if (klu.last_flag == SUNLS_SUCCESS) return "";
  switch (klu.common.status) {
    case KLU_SINGULAR:
      return "KLU found the Newton matrix singular at its last factorization (a joint or a mass the motion "
             "cannot determine at that state)";
    case KLU_OUT_OF_MEMORY:
      return "KLU ran out of memory factoring the Newton matrix";
    case KLU_TOO_LARGE:
      return "the Newton matrix's factors exceed KLU's 32-bit indices (2^31 entries): the model is too large";
    default:
      return "KLU failed (status " + std::to_string(klu.common.status) + ")";
  }
}

SUNMatrix make_klu_jacobian_matrix(SUNContext context, const std::vector<int>& column_start, const std::vector<int>& row_index) {
  const auto size = static_cast<sunindextype>(column_start.size()) - 1;
  SUNMatrix matrix = SUNSparseMatrix(size, size, static_cast<sunindextype>(row_index.size()), CSC_MAT, context);
  if (matrix == nullptr) return nullptr;
  std::copy(column_start.begin(), column_start.end(), SUNSparseMatrix_IndexPointers(matrix));
  std::copy(row_index.begin(), row_index.end(), SUNSparseMatrix_IndexValues(matrix));
  matrix->ops->zero = &keep_matrix;
  return matrix;
}

}  // namespace railcrash
