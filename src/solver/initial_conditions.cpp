#include "railcrash/solver/initial_conditions.hpp"

#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#include <Eigen/SparseQR>
#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

#include "railcrash/solver/events.hpp"

namespace railcrash {

namespace {

using SparseMatrix = Eigen::SparseMatrix<double>;

/// G (m x 3n) at q, and Phi(q).
SparseMatrix constraint_gradient(const DaeSystem& system, const double* q, Eigen::VectorXd& phi) {
  std::vector<DaeSystem::Triplet> triplets;
  phi.setZero(system.constraint_rows());
  system.constraints(q, phi.data(), &triplets);
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(triplets.size());
  for (const auto& t : triplets) entries.emplace_back(t.row, t.col, t.value);
  SparseMatrix g(system.constraint_rows(), system.body_unknowns());
  g.setFromTriplets(entries.begin(), entries.end());
  return g;
}

/// Weights W = diag(1, 1, L^2) per body.
Eigen::VectorXd assembly_weights(const DaeSystem& system) {
  const double l = system.model().length_scale();
  Eigen::VectorXd w = Eigen::VectorXd::Ones(system.body_unknowns());
  for (int i = 0; i < system.model().body_count(); ++i) w[3 * i + 2] = l * l;
  return w;
}

/// Row scale so rotational rows are measured in length units: an angle times the model's length
/// scale, for convergence tests against the round-off of its coordinates (1e-12 of it).
double row_scale(const DaeSystem& system, int row) {
  return system.constraint_row_is_rotational(row) ? system.model().length_scale() : 1.0;
}

/// The elements owning rows, at most `most` of them named ("and N more" after).
std::string describe_rows(const DaeSystem& system, const std::vector<int>& rows, std::size_t most = 1000000) {
  std::set<std::string> names;
  for (int row : rows) {
    const Element& e = system.constraint_owner(row);
    names.insert("'" + e.name() + "' (" + e.type() + (e.where().line > 0 ? ", line " + std::to_string(e.where().line) : "") + ")");
  }
  std::string out;
  std::size_t named = 0;
  for (const auto& n : names)
    if (named++ < most) out += (out.empty() ? "" : ", ") + n;
  if (names.size() > most) out += " and " + std::to_string(names.size() - most) + " more";
  return out;
}

}  // namespace

std::vector<int> dependent_constraint_rows(const DaeSystem& system, const double* q, double pivot_threshold, int& rank,
                                           RowScaling scaling) {
  const int m = system.constraint_rows();
  rank = m;
  if (m == 0) return {};
  Eigen::VectorXd phi;
  const SparseMatrix g = constraint_gradient(system, q, phi);
  SparseMatrix scaled_transpose;
  if (scaling == RowScaling::AssemblyWeights) {
    const Eigen::VectorXd root_w = assembly_weights(system).cwiseSqrt();
    scaled_transpose = (g * root_w.asDiagonal()).transpose();
  } else {
    // Angles as arcs at each body's own size (a row's angle entries, lever arms, over it), and
    // each row then of unit length: the threshold is the share of a row outside the others'
    // span, in any unit system.
    Eigen::VectorXd column_scale = Eigen::VectorXd::Ones(system.body_unknowns());
    const std::vector<double> size = system.body_angle_lengths();
    for (int i = 0; i < system.model().body_count(); ++i) column_scale[3 * i + 2] = 1.0 / size[static_cast<std::size_t>(i)];
    SparseMatrix scaled = g * column_scale.asDiagonal();
    Eigen::VectorXd row_scale = Eigen::VectorXd::Zero(m);
    for (int k = 0; k < scaled.outerSize(); ++k)
      for (SparseMatrix::InnerIterator it(scaled, k); it; ++it) row_scale[it.row()] += it.value() * it.value();
    for (int r = 0; r < m; ++r) row_scale[r] = row_scale[r] > 0.0 ? 1.0 / std::sqrt(row_scale[r]) : 1.0;
    scaled_transpose = (row_scale.asDiagonal() * scaled).transpose();
  }
  scaled_transpose.makeCompressed();
  Eigen::SparseQR<SparseMatrix, Eigen::COLAMDOrdering<int>> qr;
  qr.setPivotThreshold(pivot_threshold);
  qr.compute(scaled_transpose);
  if (qr.info() != Eigen::Success)
    throw SolverError("could not factor the constraint gradient to check the joints for redundancy");
  rank = static_cast<int>(qr.rank());
  if (rank >= m) return {};
  // (A P).col(k) = A.col(P.indices()(k)): the trailing permuted columns are the dependent
  // rows. Each is a combination x of the leading ones, R11 x = R12(:, k); the rows with a
  // non-zero weight in x are the joints it repeats.
  const Eigen::VectorXi& permutation = qr.colsPermutation().indices();
  const SparseMatrix r = qr.matrixR();
  const SparseMatrix r11 = r.topLeftCorner(rank, rank);
  std::vector<int> involved;
  for (int k = rank; k < m; ++k) {
    involved.push_back(permutation(k));
    const Eigen::VectorXd column = Eigen::VectorXd(r.block(0, k, rank, 1));
    const Eigen::VectorXd weights = r11.triangularView<Eigen::Upper>().solve(column);
    const double largest = weights.size() > 0 ? weights.cwiseAbs().maxCoeff() : 0.0;  // rank 0: no leading rows
    for (int i = 0; i < rank; ++i)
      if (std::abs(weights[i]) > 1e-8 * largest) involved.push_back(permutation(i));
  }
  return involved;
}

std::string singular_configuration(const DaeSystem& system, const double* q, double t) {
  constexpr int kLargestCheckedRows = 2000;  // a sparse QR of G^T: cheap up to here, and a failure is rare
  const int m = system.constraint_rows();
  if (m == 0) return "";
  if (m > kLargestCheckedRows)
    return "the rank check of the joints was skipped (" + std::to_string(m) + " constraint rows, more than " +
           std::to_string(kLargestCheckedRows) + ")";
  // Near a singular configuration G is nearly, not exactly, rank deficient at the last good
  // state: IDA's Newton iteration fails while the links are still a few degrees from it (the
  // IFToMM N-four-bar, N = 40, at rtol 1e-8: 0.02 rad from flat, found at 1e-2, not at 1e-3).
  constexpr double kNearlyDependent = 1e-2;  // pivot threshold on G^T, its rows of unit length (RowScaling::UnitRows)
  int rank = m;
  const std::vector<int> rows = dependent_constraint_rows(system, q, kNearlyDependent, rank, RowScaling::UnitRows);
  if (rows.empty()) return "";
  std::ostringstream msg;
  msg << "singular configuration: joints " << describe_rows(system, rows, 6) << " lose rank at t = " << t << " ("
      << m - rank << " of the " << m << " constraint equations depend on the others there)";
  return msg.str();
}

void check_constraint_rank(const DaeSystem& system, const double* q) {
  const int m = system.constraint_rows();
  if (m == 0) return;
  int rank = m;
  const std::vector<int> involved = dependent_constraint_rows(system, q, 1e-10, rank);
  if (involved.empty()) return;
  Eigen::VectorXd phi;
  constraint_gradient(system, q, phi);
  double worst = 0.0;
  for (int row : involved) worst = std::max(worst, std::abs(phi[row]) * system.constraint_row_length(row));
  const std::string file_prefix = SourceLocation{system.model().file, 0}.prefix();
  std::ostringstream msg;
  msg << file_prefix << "the joints are redundant: " << (m - rank) << " of the " << m
      << " constraint equations repeat what the others already impose, which makes the system singular. "
      << "Elements involved: " << describe_rows(system, involved) << ".";
  if (worst > 1e-9 * system.model().length_scale())
    msg << " As placed they also contradict each other (they miss by up to " << worst << " length units).";
  msg << " Remove one of them or use a joint that constrains less (e.g. a sliding_pin_joint instead of a "
         "pin_joint, or a pin_joint instead of a rigid_joint).";
  throw InputError(msg.str());
}

AssemblyReport assemble_initial_state(const DaeSystem& system, std::vector<double>& y) {
  AssemblyReport report;
  const int m = system.constraint_rows();
  const int nq = system.body_unknowns();
  if (m == 0) return report;
  check_constraint_rank(system, y.data());
  const Eigen::VectorXd w = assembly_weights(system);
  const double length = system.model().length_scale();
  const double tolerance = 1e-12 * length;
  Eigen::Map<Eigen::VectorXd> q(y.data(), nq);
  const Eigen::VectorXd q_start = q;

  Eigen::VectorXd phi;
  Eigen::SimplicialLDLT<SparseMatrix> solver;
  double worst = 0.0;
  int worst_row = 0;
  const auto measure = [&]() {
    worst = 0.0;
    for (int r = 0; r < m; ++r) {
      const double value = std::abs(phi[r]) * row_scale(system, r);
      if (value > worst) { worst = value; worst_row = r; }
    }
  };
  const int max_iterations = 50;
  for (int iteration = 0; iteration <= max_iterations; ++iteration) {
    const SparseMatrix g = constraint_gradient(system, y.data(), phi);
    measure();
    if (worst <= tolerance) break;
    if (iteration == max_iterations || !std::isfinite(worst)) {
      const Element& e = system.constraint_owner(worst_row);
      std::vector<int> missing;
      for (int r = 0; r < m; ++r)
        if (std::abs(phi[r]) * row_scale(system, r) > 1e-3 * worst) missing.push_back(r);
      std::ostringstream msg;
      msg << e.where().prefix() << "the joints cannot all be satisfied: after " << max_iterations
          << " Newton iterations on the initial positions, " << e.type() << " '" << e.name() << "' still misses by "
          << worst << " (length units); joints still open: " << describe_rows(system, missing)
          << ". Check the points and positions of the bodies they connect: they contradict each other.";
      throw InputError(msg.str());
    }
    const SparseMatrix gw = g * w.asDiagonal();
    const SparseMatrix normal = gw * g.transpose();
    solver.compute(normal);
    if (solver.info() != Eigen::Success) {
      check_constraint_rank(system, y.data());  // names the redundant joints if that is the cause
      throw InputError(SourceLocation{system.model().file, 0}.prefix() +
                       "the joints become singular while assembling the initial positions; check the joint points");
    }
    const Eigen::VectorXd x = solver.solve(phi);
    q -= gw.transpose() * x;
    report.newton_iterations = iteration + 1;
  }
  for (int i = 0; i < nq; ++i)
    report.largest_position_change =
        std::max(report.largest_position_change, std::abs(q[i] - q_start[i]) * ((i % 3 == 2) ? length : 1.0));

  // Velocity projection onto G v = 0.
  const SparseMatrix g = constraint_gradient(system, y.data(), phi);
  const SparseMatrix gw = g * w.asDiagonal();
  solver.compute(gw * g.transpose());
  Eigen::Map<Eigen::VectorXd> v(y.data() + nq, nq);
  const Eigen::VectorXd x = solver.solve(g * v);
  const Eigen::VectorXd change = gw.transpose() * x;
  v -= change;
  for (int i = 0; i < nq; ++i)
    report.largest_velocity_change = std::max(report.largest_velocity_change, std::abs(change[i]) * ((i % 3 == 2) ? length : 1.0));
  std::fill(y.begin() + 2 * nq, y.end(), 0.0);
  return report;
}

struct ConsistentRatesCache::Impl {
  Eigen::SparseLU<SparseMatrix> lu;
  std::vector<SparseMatrix::StorageIndex> outer, inner;  // the pattern lu's ordering was made for
  bool analysed = false;
  long reused = 0, analyses = 0;
};

ConsistentRatesCache::ConsistentRatesCache() : impl_(std::make_unique<Impl>()) {}
ConsistentRatesCache::~ConsistentRatesCache() = default;
long ConsistentRatesCache::reused() const { return impl_->reused; }
long ConsistentRatesCache::analysed() const { return impl_->analyses; }

void consistent_rates(const DaeSystem& system, double t, std::vector<double>& y, std::vector<double>& yp,
                      ConsistentRatesCache* cache) {
  const int nq = system.body_unknowns();
  const int m = system.constraint_rows();
  yp.assign(y.size(), 0.0);
  std::copy(y.begin() + nq, y.begin() + 2 * nq, yp.begin());  // q' = v
  std::fill(y.begin() + 2 * nq, y.end(), 0.0);                 // lambda, mu recomputed
  std::vector<Eigen::Triplet<double>> entries;
  for (int k = 0; k < nq; ++k) entries.emplace_back(k, k, system.mass_diagonal(k));
  Eigen::VectorXd constraint_rhs = Eigen::VectorXd::Zero(m);
  if (m > 0) {
    Eigen::VectorXd phi(m);
    std::vector<DaeSystem::Triplet> gradient;
    system.constraints(y.data(), phi.data(), &gradient);
    for (const auto& g : gradient) {
      entries.emplace_back(nq + g.row, g.col, g.value);
      entries.emplace_back(g.col, nq + g.row, g.value);
    }
    std::vector<double> gamma(static_cast<std::size_t>(m), 0.0);
    system.constraint_acceleration_bias(y.data(), y.data() + nq, gamma.data());
    for (int r = 0; r < m; ++r) {
      constraint_rhs[r] = -gamma[static_cast<std::size_t>(r)];
      if (!system.constraint_row_active(r)) entries.emplace_back(nq + r, nq + r, 1.0);  // lambda = 0
    }
  }
  SparseMatrix kkt(nq + m, nq + m);
  kkt.setFromTriplets(entries.begin(), entries.end());
  kkt.makeCompressed();
  // SparseLU's analyzePattern (COLAMD ordering, elimination tree) reads the pattern alone, so
  // a kept analysis of the same pattern gives the factorization compute() would.
  Eigen::SparseLU<SparseMatrix> local_lu;
  Eigen::SparseLU<SparseMatrix>& lu = cache ? cache->impl_->lu : local_lu;
  const auto* outer = kkt.outerIndexPtr();
  const auto* inner = kkt.innerIndexPtr();
  const std::size_t columns = static_cast<std::size_t>(kkt.cols()) + 1, nonzeros = static_cast<std::size_t>(kkt.nonZeros());
  if (cache && cache->impl_->analysed && cache->impl_->outer.size() == columns && cache->impl_->inner.size() == nonzeros &&
      std::equal(outer, outer + columns, cache->impl_->outer.begin()) && std::equal(inner, inner + nonzeros, cache->impl_->inner.begin())) {
    ++cache->impl_->reused;
  } else {
    lu.analyzePattern(kkt);
    if (cache) {
      cache->impl_->outer.assign(outer, outer + columns);
      cache->impl_->inner.assign(inner, inner + nonzeros);
      cache->impl_->analysed = true;
      ++cache->impl_->analyses;
    }
  }
  lu.factorize(kkt);
  if (lu.info() != Eigen::Success) {
    std::string zero;
    for (const Body& b : system.model().bodies())
      if (b.inertia == 0.0) zero += (zero.empty() ? "'" : ", '") + b.name + "'";
    throw SolverError("the equations of motion are singular at the start" +
                      (zero.empty() ? std::string(".") : ": bodies " + zero + " have zero inertia and no joint fixes their rotation; give them an inertia.") );
  }
  // Joint friction depends on the reactions: iterate on them (a contraction for friction
  // coefficients below one; a handful of passes reach round-off).
  bool friction = false;
  for (const auto& e : system.model().elements()) friction = friction || e->has_joint_force();
  std::vector<double> force(static_cast<std::size_t>(nq));
  Eigen::VectorXd rhs(nq + m), solution;
  Eigen::VectorXd previous = Eigen::VectorXd::Zero(m);
  DaeSystem::ForcesAtReactions fixed_forces;  // the forces that do not change with the reactions, once
  for (int pass = 0; pass < (friction ? 50 : 1); ++pass) {
    system.generalized_forces_at_reactions(t, y.data(), y.data() + nq, y.data() + 2 * nq, force.data(), fixed_forces);
    for (int k = 0; k < nq; ++k) rhs[k] = force[static_cast<std::size_t>(k)];
    rhs.tail(m) = constraint_rhs;
    solution = lu.solve(rhs);
    if (m == 0) break;
    for (int r = 0; r < m; ++r) y[static_cast<std::size_t>(2 * nq + r)] = solution[nq + r];
    const double change = (solution.tail(m) - previous).cwiseAbs().maxCoeff();
    previous = solution.tail(m);
    if (change <= 1e-12 * std::max(1.0, previous.cwiseAbs().maxCoeff())) break;
  }
  for (int k = 0; k < nq; ++k) yp[static_cast<std::size_t>(nq + k)] = solution[k];
}

namespace {

/// Puts every element in the mode its state y belongs to: commits the roots that are
/// negative (outside their mode), repeatedly, since one commit moves a piecewise law by one
/// segment. Returns true when a mode changed.
bool follow_modes(ModeTracker& modes, const std::vector<double>& y, std::vector<EventRecord>& events) {
  const DaeSystem& system = modes.system();
  const std::size_t count = static_cast<std::size_t>(system.root_count());
  if (count == 0) return false;
  std::vector<double> g(count);
  std::vector<int> direction(count);
  bool changed = false;
  for (int pass = 0; pass < 50; ++pass) {
    system.roots(0.0, y.data(), g.data());
    bool outside = false;
    for (std::size_t k = 0; k < count; ++k) {
      direction[k] = g[k] < 0.0 ? -1 : 0;
      outside = outside || direction[k] != 0;
    }
    if (!outside || !modes.commit_roots(0.0, y.data(), direction.data(), events)) break;
    changed = true;
  }
  return changed;
}

/// Weighted Newton projection of the positions of y onto Phi(q) = 0 (as the assembly);
/// false when it does not converge.
bool project_positions(const DaeSystem& system, std::vector<double>& y) {
  const int m = system.constraint_rows();
  if (m == 0) return true;
  const Eigen::VectorXd w = assembly_weights(system);
  const double tolerance = 1e-12 * system.model().length_scale();
  Eigen::Map<Eigen::VectorXd> q(y.data(), system.body_unknowns());
  Eigen::VectorXd phi;
  Eigen::SimplicialLDLT<SparseMatrix> solver;
  for (int iteration = 0; iteration < 20; ++iteration) {
    const SparseMatrix g = constraint_gradient(system, y.data(), phi);
    double worst = 0.0;
    for (int r = 0; r < m; ++r) worst = std::max(worst, std::abs(phi[r]) * row_scale(system, r));
    if (worst <= tolerance) return true;
    if (!std::isfinite(worst)) return false;
    const SparseMatrix gw = g * w.asDiagonal();
    solver.compute(gw * g.transpose());
    if (solver.info() != Eigen::Success) return false;
    q -= gw.transpose() * solver.solve(phi);
  }
  return false;
}

/// One thing that pushes on a body's component in a static state [force] or [force*length].
struct ForceShare {
  std::string who;  // "element 'front' (crush_spring, line 12)", "gravity", "load (line 20)"
  double value;
};

/// What pushes on every body unknown k (3 body + component) at the static state y: gravity,
/// each load, each element on the body (its forces, a joint's reaction -G^T lambda and its
/// friction). Row k's sum is minus the residual's force row k.
std::vector<std::vector<ForceShare>> forces_on_every_row(const DaeSystem& system, const std::vector<double>& y) {
  const Model& model = system.model();
  const int nq = system.body_unknowns();
  const std::size_t count = model.elements().size();
  std::vector<std::vector<ForceShare>> shares(static_cast<std::size_t>(nq));
  const auto row_of = [&](int body, int component) -> std::vector<ForceShare>& {
    return shares[static_cast<std::size_t>(3 * body + component)];
  };
  for (int b = 0; b < model.body_count(); ++b) {
    const double mass = model.bodies()[static_cast<std::size_t>(b)].mass;
    row_of(b, 0).push_back({"gravity", mass * model.gravity_x});
    row_of(b, 1).push_back({"gravity", mass * model.gravity_y});
  }
  for (const Load& load : model.loads()) {
    const int b = load.body;
    const std::array<double, 2> value = load.value.at(0.0);
    Pose<double> generalized{};
    if (load.kind == Load::Kind::Moment) {
      generalized.theta = value[0];
    } else {
      const Pose<double> pose{y[static_cast<std::size_t>(3 * b)], y[static_cast<std::size_t>(3 * b + 1)],
                              y[static_cast<std::size_t>(3 * b + 2)]};
      add_point_force(pose, load.sx, load.sy, Vec2<double>{value[0], value[1]}, generalized);
    }
    const std::string who = std::string(load.kind == Load::Kind::Moment ? "moment load" : "load") +
                            (load.where.line > 0 ? " (line " + std::to_string(load.where.line) + ")" : "");
    row_of(b, 0).push_back({who, generalized.x});
    row_of(b, 1).push_back({who, generalized.y});
    row_of(b, 2).push_back({who, generalized.theta});
  }
  // Each element's generalized forces on its slots' bodies, then the joints' reactions.
  std::vector<std::array<Pose<double>, 2>> on_slots(count);
  for (std::size_t e = 0; e < count; ++e) on_slots[e] = system.element_load(static_cast<int>(e), 0.0, y.data()).force;
  std::vector<int> owner_of_row(static_cast<std::size_t>(system.constraint_rows()), -1);
  for (std::size_t e = 0; e < count; ++e)
    for (int r = 0; r < model.elements()[e]->constraint_count(); ++r)
      owner_of_row[static_cast<std::size_t>(model.constraint_offset(e) + r)] = static_cast<int>(e);
  if (system.constraint_rows() > 0) {
    std::vector<double> phi(static_cast<std::size_t>(system.constraint_rows()));
    std::vector<DaeSystem::Triplet> gradient;
    system.constraints(y.data(), phi.data(), &gradient);
    for (const DaeSystem::Triplet& g : gradient) {
      if (!system.constraint_row_active(g.row)) continue;
      const auto e = static_cast<std::size_t>(owner_of_row[static_cast<std::size_t>(g.row)]);
      const Element& el = *model.elements()[e];
      const int body = g.col / 3, component = g.col % 3;
      const std::size_t slot = el.slot_body(0) == body ? 0 : 1;
      const double reaction = -g.value * y[static_cast<std::size_t>(2 * nq + g.row)];
      Pose<double>& f = on_slots[e][slot];
      (component == 0 ? f.x : component == 1 ? f.y : f.theta) += reaction;
    }
  }
  for (std::size_t e = 0; e < count; ++e) {
    const Element& el = *model.elements()[e];
    const std::string who = "element '" + el.name() + "' (" + el.type() +
                            (el.where().line > 0 ? ", line " + std::to_string(el.where().line) : std::string()) + ")";
    for (std::size_t slot = 0; slot < 2; ++slot) {
      const int b = el.slot_body(static_cast<int>(slot));
      if (b == kGround || (slot == 1 && el.slot_body(0) == b)) continue;  // (both slots on one body: once)
      Pose<double> f = on_slots[e][slot];
      if (slot == 0 && el.slot_body(1) == b) f = {f.x + on_slots[e][1].x, f.y + on_slots[e][1].y, f.theta + on_slots[e][1].theta};
      row_of(b, 0).push_back({who, f.x});
      row_of(b, 1).push_back({who, f.y});
      row_of(b, 2).push_back({who, f.theta});
    }
  }
  return shares;
}

/// Why the settle stopped short: the largest unbalance (a force row, in the model's terms:
/// body, direction, value and what pushes there, largest first; or a joint's gap), instead of
/// assuming gravity. r: the residual at the state; shares: forces_on_every_row there.
std::string unsettled_message(const DaeSystem& system, const std::vector<double>& r,
                              const EquilibriumReport& report, double force_scale,
                              const std::vector<std::vector<ForceShare>>& shares) {
  const Model& model = system.model();
  const int nq = system.body_unknowns(), m = system.constraint_rows();
  const double length = model.length_scale();
  // Largest part of the unbalance measure: a force row over the force scale (moments over
  // length times it), or a joint row over the length scale.
  int worst = 0;
  double worst_measure = -1.0;
  for (int k = 0; k < nq + m; ++k) {
    const double value = std::abs(r[static_cast<std::size_t>(nq + k)]);
    const double measure = k < nq ? value / (force_scale * (k % 3 == 2 ? length : 1.0)) : value / length;
    if (measure > worst_measure) worst = k, worst_measure = measure;
  }
  std::ostringstream msg;
  msg << "no static equilibrium found: after " << report.steps << " steps ";
  if (worst >= nq) {
    const int row = worst - nq;
    const Element& joint = system.constraint_owner(row);
    int first_row = 0;  // the joint's first constraint row
    for (std::size_t e = 0; e < model.elements().size(); ++e)
      if (model.elements()[e].get() == &joint) first_row = model.constraint_offset(e);
    msg << "the largest unbalance is a gap: " << joint.where().prefix() << "joint '" << joint.name() << "' ("
        << joint.type() << ") is open by " << r[static_cast<std::size_t>(2 * nq + row)] << " in its constraint row "
        << row - first_row + 1 << "; check that its points can meet with the other joints closed, or set "
        << "static_equilibrium: false to start from the given positions";
    return msg.str();
  }
  const Body& body = model.bodies()[static_cast<std::size_t>(worst / 3)];
  static const char* const kDirection[3] = {"x", "y", "theta"};
  const char* direction = kDirection[worst % 3];
  const double unbalanced = -r[static_cast<std::size_t>(nq + worst)];
  msg << "the largest unbalanced " << (worst % 3 == 2 ? "moment" : "force") << " is " << unbalanced << " in " << direction
      << " on " << body.where.prefix() << "body '" << body.name << "' (the settle's force scale is " << force_scale
      << ", its tolerance 1e-10 of that). On that body in " << direction << ":";
  std::vector<ForceShare> list = shares[static_cast<std::size_t>(worst)];
  std::stable_sort(list.begin(), list.end(),
                   [](const ForceShare& a, const ForceShare& b) { return std::abs(a.value) > std::abs(b.value); });
  std::size_t shown = 0;
  for (const ForceShare& s : list) {
    if (s.value == 0.0 || shown == 5) continue;
    msg << (shown++ ? ", " : " ") << s.who << " " << s.value;
  }
  if (shown == 0) msg << " nothing";
  if (shown < list.size()) {
    std::size_t rest = 0;
    for (const ForceShare& s : list) rest += s.value != 0.0;
    if (rest > shown) msg << " and " << rest - shown << " more";
  }
  msg << ". Nothing in the model balances these in " << direction
      << " (a missing spring, joint, contact or wheel in that direction has no equilibrium; so has a load no element "
         "resists); set static_equilibrium: false to start from the given positions";
  return msg.str();
}

}  // namespace

EquilibriumReport settle_static_equilibrium(DaeSystem& system, std::vector<double>& y,
                                            std::vector<EventRecord>& events) {
  EquilibriumReport report;
  const int n = system.size();
  const int nq = system.body_unknowns();
  const int m = system.constraint_rows();
  const double length = system.model().length_scale();
  const std::vector<double> start(y.begin(), y.begin() + nq);
  const std::vector<double> velocities(y.begin() + nq, y.begin() + 2 * nq);
  std::fill(y.begin() + nq, y.begin() + 2 * nq, 0.0);  // a static state has no velocity
  const std::vector<double> yp(static_cast<std::size_t>(n), 0.0);
  std::vector<double> r(static_cast<std::size_t>(n));

  // Every element in the mode of the starting state (a spring assembled past a breakpoint).
  ModeTracker modes(system);  // the settle's every write of the element modes
  std::vector<EventRecord> changes;
  follow_modes(modes, y, changes);
  for (EventRecord& e : changes) e.what = "static equilibrium: " + e.what;
  events.insert(events.end(), changes.begin(), changes.end());

  // Scale of the forces to balance: the weights, or else the largest initial force.
  std::vector<double> f(static_cast<std::size_t>(nq));
  system.generalized_forces(0.0, y.data(), y.data() + nq, f.data(), nullptr, nullptr, y.data() + 2 * nq);
  double force_scale = 0.0;
  for (const Body& b : system.model().bodies())
    force_scale += b.mass * std::hypot(system.model().gravity_x, system.model().gravity_y);
  for (double value : f) force_scale = std::max(force_scale, std::abs(value));
  if (!(force_scale > 0.0)) {  // nothing to balance
    std::copy(velocities.begin(), velocities.end(), y.begin() + nq);
    return report;
  }
  // Unbalance measure: root-sum-square of the forces over their scale and the joint gaps
  // over the model size; residual_force receives the largest single unbalanced force.
  const auto unbalance = [&](const std::vector<double>& state, double* residual_force) {
    system.residual(0.0, state.data(), yp.data(), r.data());
    double sum = 0.0, largest = 0.0;
    for (int k = 0; k < nq; ++k) {
      const double force = std::abs(r[static_cast<std::size_t>(nq + k)]) * (k % 3 == 2 ? 1.0 / length : 1.0);
      largest = std::max(largest, force);
      sum += (force / force_scale) * (force / force_scale);
    }
    for (int k = 0; k < m; ++k) sum += std::pow(r[static_cast<std::size_t>(2 * nq + k)] / length, 2);
    if (residual_force) *residual_force = largest;
    return std::sqrt(sum);
  };

  const SparsePattern& pattern = system.pattern();
  std::vector<double> values(static_cast<std::size_t>(pattern.nonzeros()));
  // Unknown / equation map: q -> 0..nq-1, lambda -> nq..nq+m-1; rows: r_v -> 0..nq-1, r_phi -> nq..
  const auto local_column = [&](int col) { return col < nq ? col : (col >= 2 * nq && col < 2 * nq + m ? nq + col - 2 * nq : -1); };
  const auto local_row = [&](int row) {
    return (row >= nq && row < 2 * nq) ? row - nq : (row >= 2 * nq && row < 2 * nq + m ? nq + row - 2 * nq : -1);
  };
  double step = 1e-3;                // pseudo-time step h [time]
  const double smallest_step = 1e-12;
  // Trust region per step: translations within 0.05 % of the model size, rotations 0.01 rad,
  // so that the settle follows the state down as a heavily damped motion would (a light body
  // in a stiff, nearly singular corner must not spin or fly off in one step, and a long
  // step must not jump to a distant equilibrium of a model that has several). While it
  // binds, h shrinks (M / h^2 then holds back the soft directions) instead of growing.
  const double largest_move = 5e-4 * length, largest_turn = 0.01;
  // Work below this is round-off (and the joints' own residual times their reactions) [force*length].
  const double work_noise = 1e-10 * force_scale * length;
  double current = unbalance(y, &report.residual_force);
  const double tolerance = 1e-10;
  Eigen::SparseLU<SparseMatrix> lu;
  const int max_steps = 2000;
  for (; report.steps < max_steps && current > tolerance; ++report.steps) {
    system.jacobian(0.0, 0.0, y.data(), yp.data(), values.data());
    std::vector<Eigen::Triplet<double>> entries;
    for (int col = 0; col < n; ++col) {
      const int lc = local_column(col);
      if (lc < 0) continue;
      for (int k = pattern.column_start[static_cast<std::size_t>(col)]; k < pattern.column_start[static_cast<std::size_t>(col + 1)]; ++k) {
        const int lr = local_row(pattern.row_index[static_cast<std::size_t>(k)]);
        if (lr >= 0) entries.emplace_back(lr, lc, values[static_cast<std::size_t>(k)]);
      }
    }
    for (int k = 0; k < nq; ++k) entries.emplace_back(k, k, system.mass_diagonal(k) / (step * step));
    SparseMatrix a(nq + m, nq + m);
    a.setFromTriplets(entries.begin(), entries.end());
    a.makeCompressed();
    lu.compute(a);
    system.residual(0.0, y.data(), yp.data(), r.data());
    Eigen::VectorXd rhs(nq + m);
    for (int k = 0; k < nq; ++k) rhs[k] = -r[static_cast<std::size_t>(nq + k)];
    for (int k = 0; k < m; ++k) rhs[nq + k] = -r[static_cast<std::size_t>(2 * nq + k)];
    Eigen::VectorXd delta;
    if (lu.info() == Eigen::Success) delta = lu.solve(rhs);
    if (lu.info() != Eigen::Success || !delta.allFinite()) {
      if ((step *= 0.25) < smallest_step) break;
      continue;
    }
    double shrink = 1.0;
    for (int k = 0; k < nq; ++k) {
      const double limit = (k % 3 == 2) ? largest_turn : largest_move;
      if (std::abs(delta[k]) * shrink > limit) shrink = limit / std::abs(delta[k]);
    }
    delta *= shrink;
    std::vector<double> trial = y;
    for (int k = 0; k < nq; ++k) trial[static_cast<std::size_t>(k)] += delta[k];
    for (int k = 0; k < m; ++k) trial[static_cast<std::size_t>(2 * nq + k)] += delta[nq + k];
    // The trial state on the joints, with every element in the mode the trial state is in
    // (from the modes and histories of y, restored when the step is rejected).
    const ElementStates::Snapshot modes_at_y = modes.snapshot();
    changes.clear();
    const bool on_joints = project_positions(system, trial);
    if (on_joints) follow_modes(modes, trial, changes);
    double work = 0.0, next = 0.0;
    if (on_joints) {
      const std::vector<double> r_here = r;  // residual at y (from the Newton right-hand side)
      next = unbalance(trial, nullptr);     // leaves the residual at the trial state in r
      for (int k = 0; k < nq; ++k) {
        const auto kk = static_cast<std::size_t>(k);
        work -= 0.5 * (r_here[kk + static_cast<std::size_t>(nq)] + r[kk + static_cast<std::size_t>(nq)]) * (trial[kk] - y[kk]);
      }
    }
    // Accept a step along which the unbalanced forces do work (trapezoidal rule over the
    // step: exact for a quadratic energy, and it needs no energy of non-conservative laws).
    // The forces then push the state down the energy of the model, which is continuously
    // differentiable across the kinks of piecewise-linear laws where the force balance is
    // not, so the descent does not stall on a kink; a step that overshoots into a stiff
    // segment meets a large opposing force at its end and is shortened. Once the work is
    // round-off, the unbalance must fall instead (Newton's last steps).
    const bool accept = on_joints && std::isfinite(next) &&
                        (work > work_noise || (work >= -work_noise && next <= current));
    if (!accept) {
      modes.restore(modes_at_y);  // back to the modes and histories of y
      current = unbalance(y, nullptr);
      if ((step *= 0.25) < smallest_step) break;
      continue;
    }
    y = trial;
    current = next;
    step = shrink < 1.0 ? step * 0.5 : std::min(step * 2.0, 1e6);
    for (EventRecord& e : changes) e.what = "static equilibrium: " + e.what;
    events.insert(events.end(), changes.begin(), changes.end());
  }
  current = unbalance(y, &report.residual_force);
  if (current > tolerance) {
    // Is what is left round-off? Each force row is a sum of what gravity, the loads, the
    // elements and the joints' reactions put on one body component; where those are large
    // (preloaded springs, stiff contacts pressed together), that sum cannot come out closer to
    // zero than about 1e-16 of them. A force row within 1e-10 of its own sum of magnitudes
    // (the settle's relative tolerance, on the forces that meet there) is balanced.
    std::vector<double> unbalanced(static_cast<std::size_t>(nq)), magnitude(static_cast<std::size_t>(nq));
    const std::vector<std::vector<ForceShare>> shares = forces_on_every_row(system, y);
    bool round_off = true;
    for (int k = 0; k < nq; ++k) {
      const auto kk = static_cast<std::size_t>(k);
      unbalanced[kk] = -r[static_cast<std::size_t>(nq + k)];
      for (const ForceShare& s : shares[kk]) magnitude[kk] += std::abs(s.value);
      if (std::abs(unbalanced[kk]) > 1e-10 * std::max(magnitude[kk], force_scale * (k % 3 == 2 ? length : 1.0)))
        round_off = false;
    }
    for (int row = 0; row < m; ++row)
      if (std::abs(r[static_cast<std::size_t>(2 * nq + row)]) > tolerance * length) round_off = false;
    if (!round_off) throw SolverError(unsettled_message(system, r, report, force_scale, shares));
  }
  for (int k = 0; k < nq; ++k)
    report.largest_position_change = std::max(report.largest_position_change,
                                              std::abs(y[static_cast<std::size_t>(k)] - start[static_cast<std::size_t>(k)]) *
                                                  ((k % 3 == 2) ? length : 1.0));
  std::copy(velocities.begin(), velocities.end(), y.begin() + nq);
  return report;
}

StartReport prepare_start(DaeSystem& system, std::vector<double>& y, std::vector<EventRecord>& events, bool static_equilibrium) {
  StartReport report;
  ModeTracker(system).reset_modes();
  y = system.initial_state();
  report.assembly = assemble_initial_state(system, y);
  if (static_equilibrium) {
    report.equilibrium = settle_static_equilibrium(system, y, events);
    const AssemblyReport projection = assemble_initial_state(system, y);
    report.assembly.largest_velocity_change = std::max(report.assembly.largest_velocity_change, projection.largest_velocity_change);
  }
  return report;
}

}  // namespace railcrash
