#include <catch2/catch.hpp>

#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <array>
#include <cmath>
#include <vector>

#include "../../src/solver/klu_solver.hpp"

using namespace railcrash;

namespace {

// A 4 x 4 matrix that needs pivoting (a zero diagonal), in CSC form:
//   [ 0  2  0  1 ]
//   [ 3  0  1  0 ]
//   [ 0  1  4  0 ]
//   [ 1  0  0  5 ]
const std::vector<int> kColumnStart{0, 2, 4, 6, 8};
const std::vector<int> kRowIndex{1, 3, 0, 2, 1, 2, 0, 3};
const std::array<double, 8> kValues{3, 1, 2, 1, 1, 4, 1, 5};

/// b = A x for the CSC matrix of kColumnStart / kRowIndex with the given values.
std::vector<double> times(const std::array<double, 8>& values, const std::vector<double>& x) {
  std::vector<double> b(x.size(), 0.0);
  for (std::size_t column = 0; column + 1 < kColumnStart.size(); ++column)
    for (int k = kColumnStart[column]; k < kColumnStart[column + 1]; ++k)
      b[static_cast<std::size_t>(kRowIndex[static_cast<std::size_t>(k)])] += values[static_cast<std::size_t>(k)] * x[column];
  return b;
}

struct Sundials {
  SUNContext context = nullptr;
  SUNMatrix matrix = nullptr;
  SUNLinearSolver solver = nullptr;
  N_Vector x = nullptr, b = nullptr;
  Sundials() {
    REQUIRE(SUNContext_Create(nullptr, &context) == 0);
    matrix = make_klu_jacobian_matrix(context, kColumnStart, kRowIndex);
    solver = make_klu_solver(context, kColumnStart, kRowIndex, nullptr);
    x = N_VNew_Serial(4, context);
    b = N_VNew_Serial(4, context);
    REQUIRE(matrix != nullptr);
    REQUIRE(solver != nullptr);
  }
  ~Sundials() {
    N_VDestroy(x);
    N_VDestroy(b);
    SUNLinSolFree(solver);
    SUNMatDestroy(matrix);
    SUNContext_Free(&context);
  }
  void set(const std::array<double, 8>& values) {
    double* data = SUNSparseMatrix_Data(matrix);
    for (std::size_t k = 0; k < values.size(); ++k) data[k] = values[k];
  }
  /// Solves A x = A x_true and returns the largest error of x.
  double error_of_solve(const std::array<double, 8>& values, int& flag) {
    const std::vector<double> truth{1.0, -2.0, 3.0, 4.0};
    const std::vector<double> rhs = times(values, truth);
    for (std::size_t k = 0; k < 4; ++k) N_VGetArrayPointer(b)[k] = rhs[k];
    flag = SUNLinSolSolve(solver, matrix, x, b, 0.0);
    double worst = 0.0;
    for (std::size_t k = 0; k < 4; ++k) worst = std::max(worst, std::abs(N_VGetArrayPointer(x)[k] - truth[k]));
    return worst;
  }
};

}  // namespace

TEST_CASE("KLU with 32-bit indices solves, refactors, falls back to pivoting and reports singular matrices", "[klu]") {
  Sundials s;
  CHECK(SUNLinSolGetType(s.solver) == SUNLINEARSOLVER_DIRECT);
  CHECK(klu_factor_entries(s.solver) == 0);  // nothing factored yet
  REQUIRE(SUNLinSolInitialize(s.solver) == SUNLS_SUCCESS);

  // First setup: analysis and factorization with partial pivoting.
  s.set(kValues);
  REQUIRE(SUNLinSolSetup(s.solver, s.matrix) == SUNLS_SUCCESS);
  CHECK(klu_factor_entries(s.solver) >= 8);
  int flag = -1;
  CHECK(s.error_of_solve(kValues, flag) < 1e-14);
  CHECK(flag == SUNLS_SUCCESS);

  // New values, same pattern: a refactorization with the kept pivot order.
  const std::array<double, 8> nearby{3.5, 1, 2, 0.5, 1, 4.5, 1, 5};
  s.set(nearby);
  REQUIRE(SUNLinSolSetup(s.solver, s.matrix) == SUNLS_SUCCESS);
  CHECK(s.error_of_solve(nearby, flag) < 1e-14);

  // A restart's initialize keeps the analysis; the pivots chosen for the first values are now
  // tiny (pivot growth 1e12): the setup factors afresh and the solution stays accurate.
  REQUIRE(SUNLinSolInitialize(s.solver) == SUNLS_SUCCESS);
  const std::array<double, 8> repivot{1e-12, 1, 1e-12, 1, 1, 1e-12, 1, 1e-12};
  s.set(repivot);
  REQUIRE(SUNLinSolSetup(s.solver, s.matrix) == SUNLS_SUCCESS);
  CHECK(s.error_of_solve(repivot, flag) < 1e-9);

  // IDA zeroes the matrix before each Jacobian: here that leaves the pattern (and values) alone.
  REQUIRE(SUNMatZero(s.matrix) == 0);
  for (std::size_t k = 0; k < kRowIndex.size(); ++k) CHECK(SUNSparseMatrix_IndexValues(s.matrix)[k] == kRowIndex[k]);
  for (std::size_t k = 0; k < kColumnStart.size(); ++k) CHECK(SUNSparseMatrix_IndexPointers(s.matrix)[k] == kColumnStart[k]);

  // A singular matrix (column 2 all zero) is a recoverable failure: IDA cuts its step.
  std::array<double, 8> singular = kValues;
  singular[4] = singular[5] = 0.0;
  s.set(singular);
  CHECK(SUNLinSolSetup(s.solver, s.matrix) == SUNLS_PACKAGE_FAIL_REC);
  CHECK(SUNLinSolLastFlag(s.solver) == SUNLS_PACKAGE_FAIL_REC);
  CHECK_THAT(klu_failure(s.solver), Catch::Contains("singular"));

  // ... and the solver recovers when the values do.
  s.set(kValues);
  REQUIRE(SUNLinSolSetup(s.solver, s.matrix) == SUNLS_SUCCESS);
  CHECK(klu_failure(s.solver).empty());
  CHECK(s.error_of_solve(kValues, flag) < 1e-14);
}
