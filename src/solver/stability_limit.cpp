#include "railcrash/solver/stability_limit.hpp"

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <limits>

namespace railcrash {

namespace {

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

double explicit_stability_limit(const DaeSystem& system, const std::vector<double>& y, const PenaltyRows* penalty) {
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

}  // namespace railcrash
