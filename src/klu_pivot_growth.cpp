#include "klu_pivot_growth.hpp"

#include <cassert>

namespace railcrash {

namespace {

/// KLU's magnitude (SCALAR_ABS): x for x >= 0 and NaN, -x for x < 0.
inline double magnitude(double x) { return x < 0 ? -x : x; }

/// Doubles (KLU's "Unit") taken by `count` ints in KLU's packed factors: U's row indices of a
/// column come first, rounded up to whole doubles, then its values.
inline int units_of_ints(int count) {
  return static_cast<int>((sizeof(int) * static_cast<std::size_t>(count) + sizeof(double) - 1) / sizeof(double));
}

}  // namespace

void PivotGrowth::gather(const int* column_start, const int* row_index, const klu_symbolic& symbolic,
                         const klu_numeric& numeric) {
  clear();
  row_scale_ = numeric.Rs;
  const auto* diagonal = static_cast<const double*>(numeric.Udiag);
  for (int block = 0; block < symbolic.nblocks; ++block) {
    const int first = symbolic.R[block];  // the block's columns, in KLU's order
    const int end = symbolic.R[block + 1];
    if (end - first == 1) continue;  // klu_rgrowth skips singleton blocks
    const auto* packed = static_cast<const double*>(numeric.LUbx[block]);
    for (int column = first; column < end; ++column) {
      Column listed{};
      listed.first_entry = static_cast<int>(entry_.size());
      const int original_column = symbolic.Q[column];
      for (int k = column_start[original_column]; k < column_start[original_column + 1]; ++k) {
        const int pivotal_row = numeric.Pinv[row_index[k]];
        if (pivotal_row < first) continue;  // left of the block: in the off-diagonal part
        assert(pivotal_row < end);
        entry_.push_back(k);
        entry_scale_row_.push_back(pivotal_row);
      }
      listed.end_entry = static_cast<int>(entry_.size());
      listed.u_length = numeric.Ulen[column];  // Uip: the column's place in its block's packed factors
      listed.u_values = packed + numeric.Uip[column] + units_of_ints(listed.u_length);
      listed.u_diagonal = diagonal + column;
      columns_.push_back(listed);
    }
  }
  gathered_ = true;
}

void PivotGrowth::clear() {
  columns_.clear();
  entry_.clear();
  entry_scale_row_.clear();
  row_scale_ = nullptr;
  gathered_ = false;
}

double PivotGrowth::operator()(const double* values) const {
  assert(gathered_);
  double growth = 1;
  for (const Column& column : columns_) {
    double largest_a = 0;
    if (row_scale_ != nullptr) {
      for (int e = column.first_entry; e < column.end_entry; ++e) {
        const double scaled = values[entry_[e]] / row_scale_[entry_scale_row_[e]];
        const double size = magnitude(scaled);
        if (size > largest_a) largest_a = size;
      }
    } else {
      for (int e = column.first_entry; e < column.end_entry; ++e) {
        const double size = magnitude(values[entry_[e]]);
        if (size > largest_a) largest_a = size;
      }
    }
    double largest_u = 0;
    for (int k = 0; k < column.u_length; ++k) {
      const double size = magnitude(column.u_values[k]);
      if (size > largest_u) largest_u = size;
    }
    const double pivot = magnitude(*column.u_diagonal);
    if (pivot > largest_u) largest_u = pivot;
    if (largest_u == 0) continue;  // klu_rgrowth skips a column whose U is zero
    const double ratio = largest_a / largest_u;
    if (ratio < growth) growth = ratio;
  }
  return growth;
}

}  // namespace railcrash
