#pragma once
// KLU's reciprocal pivot growth, read with the loops gathered once per pivot order.
//
// After a refactorization with kept pivots (klu_refactor) the solver asks whether those pivots
// are still sound. KLU's answer is klu_rgrowth: for each column j of each block of the block
// triangular form that is larger than 1 x 1,
//
//   growth_j = max_i |A(p_i, q_j) / R_i|  /  max_i |U(i, j)|          (columns with U(:, j) = 0 skipped)
//
// where A(p, q) is the matrix in KLU's row and column order, R the row scale factors of the
// refactorization and U its upper factor (diagonal included); the result is the smallest
// growth_j, and 1 when every growth_j is larger or there is no such column.
//
// klu_rgrowth finds each column's entries through the column permutation Q and the inverse row
// permutation Pinv on every call, skipping the entries left of the block. Between two full
// factorizations neither permutation changes, so PivotGrowth lists, once, each column's entries
// (their places in A's values and their scale factors) and the place of U's column in KLU's
// packed factors; every call then streams through those lists. The divisions, magnitudes and
// comparisons are KLU's, one for one, and min and max do not depend on the order in which
// they are taken, so the result is klu_rgrowth's bit for bit (tests/test_klu_solver.cpp
// checks this on matrices of several blocks). It is 5 % of the barrier test's run with
// klu_rgrowth (bench/README.md, "KLU's pivot growth").

#include <klu.h>

#include <vector>

namespace railcrash {

class PivotGrowth {
 public:
  /// Lists the columns of the factorization `numeric` of the CSC pattern (column_start,
  /// row_index) analysed as `symbolic`. Valid until `numeric` is freed or factored afresh.
  void gather(const int* column_start, const int* row_index, const klu_symbolic& symbolic, const klu_numeric& numeric);

  /// Forgets the lists (the factorization they describe is gone).
  void clear();

  /// True when the lists describe a factorization.
  bool gathered() const { return gathered_; }

  /// klu_rgrowth's value (Common->rgrowth) for the matrix values `values` (in the pattern's
  /// order) just refactored into the gathered factorization.
  double operator()(const double* values) const;

 private:
  struct Column {
    int first_entry;     // into entry_/entry_scale_row_: this column's entries in the block
    int end_entry;
    const double* u_values;    // U's off-diagonal entries of the column in KLU's packed factors
    int u_length;              // their number
    const double* u_diagonal;  // U(j, j)
  };
  std::vector<Column> columns_;
  std::vector<int> entry_;            // position in A's values
  std::vector<int> entry_scale_row_;  // the entry's pivotal row, the index of its scale factor
  const double* row_scale_ = nullptr;  // numeric.Rs (null when KLU does not scale)
  bool gathered_ = false;
};

}  // namespace railcrash
