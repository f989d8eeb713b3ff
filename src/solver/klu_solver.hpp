#pragma once
// IDA's linear solver: KLU (SuiteSparse) with 32-bit indices, as a SUNDIALS SUNLinearSolver.
//
// SUNDIALS' own KLU module (SUNLinSol_KLU) calls KLU's 64-bit-index interface (klu_l_*),
// because Debian builds SUNDIALS with 64-bit sunindextype. Each stored entry of KLU's factors
// then costs 16 bytes, index and value; with KLU's 32-bit interface (klu_*) it costs 12. The
// algorithms are the same source compiled twice, so the factors, pivots and solutions are the
// same bit for bit; only the memory a factorization and a solve stream through shrinks. On a
// long consist that memory outgrows the cache (bench/HISTORY.md, "Where a long consist's time
// goes, phase by phase"), where bytes are time.
//
// The solver also does what railcrash used to patch into SUNLinSol_KLU:
//  - the first analysis tries KLU's AMD and COLAMD orderings and keeps the one whose factors
//    hold fewer entries (SUNDIALS' module uses COLAMD alone), unless one is named;
//  - initialize keeps a symbolic analysis once made (a restart's IDAReInit would redo the
//    ordering of a matrix whose pattern never changes);
//  - setup refactors with the previous pivot order, and factors afresh (partial pivoting) when
//    the refactorization fails or, at a setup the caller marks
//    (klu_check_pivot_growth_at_next_setup: IDA's after a failed Newton iteration), when KLU's
//    reciprocal pivot growth has fallen below 1e-8. SUNDIALS' module judges every setup by
//    condition estimates, which the GGL Jacobian of a crash model, mixing masses, inertias and
//    multiplier rows over many decades, always fails: every setup paid for three
//    factorizations. The growth check at every setup, as before, never once factored afresh
//    on any shipped model at its own settings, and cost 7 % of IDA's CPU on mu_3plus3_si
//    (bench/HISTORY.md, "Pivot growth checked after Newton failures");
//  - setup and solve are timed as Phase::LinearSetup and Phase::LinearSolve when the run is.
//
// The matrix handed to setup and solve is IDA's SUNSparseMatrix (CSC): its values are read in
// place; its pattern is the `column_start` / `row_index` given at creation, held here in 32-bit
// indices, which is why the matrix's own index arrays are neither read nor rewritten
// (make_klu_jacobian_matrix).

#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>
#include <sundials/sundials_matrix.h>

#include <string>
#include <vector>

namespace railcrash {

class PhaseClock;

/// Which fill-reducing ordering the first analysis keeps: AMD or COLAMD, whichever factors the
/// first matrix with fewer entries (a tie keeps AMD), or the one named.
enum class KluOrdering { FewestEntries, Amd, Colamd };

/// A KLU solver for n x n matrices of the given CSC pattern (column_start has n + 1 entries).
/// `clock` (may be null) times setup and solve. The caller frees it with SUNLinSolFree.
SUNLinearSolver make_klu_solver(SUNContext context, const std::vector<int>& column_start, const std::vector<int>& row_index,
                                PhaseClock* clock, KluOrdering ordering = KluOrdering::FewestEntries);

/// Asks the next setup to check the kept pivot order's growth (klu_setup) before using it.
/// A refactorization whose pivots have grown makes an inaccurate Newton matrix, which shows as
/// a Newton iteration that fails: the setup after one is where the check pays.
void klu_check_pivot_growth_at_next_setup(SUNLinearSolver solver);

/// The entries KLU stores for the last factorization (L, U and the off-diagonal blocks of its
/// block triangular form); 0 before the first.
long klu_factor_entries(SUNLinearSolver solver);

/// The fill-reducing ordering the first analysis chose, "AMD" or "COLAMD" (the one whose first
/// factorization held fewer entries); "" before the first.
std::string klu_ordering(SUNLinearSolver solver);

/// Why the solver's last setup or solve failed, for a failure message ("" when it did not).
std::string klu_failure(SUNLinearSolver solver);

/// IDA's n x n CSC Jacobian matrix of the given pattern, with its index arrays written once.
/// Its zero operation (called by IDA before every Jacobian evaluation) is replaced by one that
/// leaves the matrix as it is: the Jacobian function overwrites every value, and the index
/// arrays, which SUNDIALS' zero would clear, never change. The caller frees it with SUNMatDestroy.
SUNMatrix make_klu_jacobian_matrix(SUNContext context, const std::vector<int>& column_start, const std::vector<int>& row_index);

}  // namespace railcrash
