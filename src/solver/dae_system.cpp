#include "railcrash/solver/dae_system.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

namespace railcrash {

namespace {

/// Records (row, col) of every addition: the dry run that learns the pattern.
struct PatternRecorder {
  std::vector<std::pair<int, int>> entries;  // (col, row)
  void add(int row, int col, double) { entries.emplace_back(col, row); }
  void begin_element(int) {}
};

/// Adds values through the slots learned by the dry run.
struct SlotWriter {
  const int* slot;
  double* values;
  void add(int, int, double value) { values[*slot++] += value; }
  void begin_element(int) {}
};

/// Finds the first non-finite Jacobian entry and who added it (element index; -1: bodies, loads).
struct NonFiniteFinder {
  int owner = -1;  // of the additions now
  int found_owner = -1, row = -1, col = -1;
  double value = 0.0;
  bool found = false;
  void add(int r, int c, double v) {
    if (found || std::isfinite(v)) return;
    found = true, found_owner = owner, row = r, col = c, value = v;
  }
  void begin_element(int e) { owner = e; }
};

std::array<Pose<double>, 2> gather_poses(const Element& e, const double* q) {
  std::array<Pose<double>, 2> poses{};
  for (int k = 0; k < 2; ++k) {
    const int b = e.slot_body(k);
    if (b != kGround) poses[static_cast<std::size_t>(k)] = {q[3 * b], q[3 * b + 1], q[3 * b + 2]};
  }
  return poses;
}

double& component(Pose<double>& p, int c) { return c == 0 ? p.x : (c == 1 ? p.y : p.theta); }
double component(const Pose<double>& p, int c) { return c == 0 ? p.x : (c == 1 ? p.y : p.theta); }

/// Calls visit(global_row, global_col, local_row, local_col) for every pair of components
/// of the element's non-ground bodies: global indices are body unknowns (3 body + component),
/// local ones the element's 6 (3 slot + component).
template <class Visit>
void for_each_body_pair(const Element& el, Visit visit) {
  for (int a = 0; a < 2; ++a) {
    const int ba = el.slot_body(a);
    if (ba == kGround) continue;
    for (int b = 0; b < 2; ++b) {
      const int bb = el.slot_body(b);
      if (bb == kGround) continue;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          visit(3 * ba + i, 3 * bb + j, static_cast<std::size_t>(3 * a + i), static_cast<std::size_t>(3 * b + j));
    }
  }
}

/// The element's rates as one local vector (vx, vy, omega of slot 0, then slot 1).
void flatten_rates(const ElementState<double>& s, double local_v[6]) {
  for (int k = 0; k < 2; ++k)
    for (int c = 0; c < 3; ++c) local_v[3 * k + c] = component(s.v[static_cast<std::size_t>(k)], c);
}

}  // namespace

EnergyBalance EnergyBalance::between(const EnergyState& start, const EnergyState& now) {
  EnergyBalance b;
  b.kinetic = now.kinetic;
  b.elastic = now.elastic;
  b.gravity = now.gravity - start.gravity;
  // Each element that can dissipate now: work done on it less the change of its stored energy.
  // A conservative element (an elastic spring, a frictionless joint) adds nothing: the
  // difference between its work quadrature and its stored energy is integration drift.
  const auto at = [](const std::vector<double>& values, std::size_t e) { return e < values.size() ? values[e] : 0.0; };
  double dissipated = (now.penalty_work - start.penalty_work) - (now.penalty_elastic - start.penalty_elastic);
  for (std::size_t e = 0; e < now.element_dissipates.size(); ++e)
    if (now.element_dissipates[e])
      dissipated += (at(now.element_work_done, e) - at(start.element_work_done, e)) -
                    (at(now.element_elastic, e) - at(start.element_elastic, e));
  b.dissipated = dissipated;
  b.external_work = now.load_work - start.load_work;
  b.initial_total = start.kinetic + start.elastic;
  return b;
}

namespace {

/// Each body's size [length]: the larger of its radius of gyration and its farthest connection
/// point; 0 for a point mass without offset connections.
std::vector<double> body_sizes(const Model& model) {
  std::vector<double> size(static_cast<std::size_t>(model.body_count()), 0.0);
  for (int i = 0; i < model.body_count(); ++i) {
    const Body& b = model.bodies()[static_cast<std::size_t>(i)];
    if (b.mass > 0.0 && b.inertia > 0.0) size[static_cast<std::size_t>(i)] = std::sqrt(b.inertia / b.mass);
  }
  for (const auto& element : model.elements())
    for (const PointRef& p : element->points())
      if (p.body != kGround) {
        double& r = size[static_cast<std::size_t>(p.body)];
        r = std::max(r, std::hypot(p.sx, p.sy));
      }
  return size;
}

}  // namespace

DaeSystem::DaeSystem(const Model& model) : model_(model), modes_(model) {
  RAILCRASH_DEMAND(model.finalized());
  const int n = model.body_count();
  mass_.resize(static_cast<std::size_t>(3 * n));
  rotation_angle_.assign(static_cast<std::size_t>(n), std::numeric_limits<double>::quiet_NaN());
  rotation_.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const Body& b = model.bodies()[static_cast<std::size_t>(i)];
    mass_[static_cast<std::size_t>(3 * i)] = b.mass;
    mass_[static_cast<std::size_t>(3 * i + 1)] = b.mass;
    mass_[static_cast<std::size_t>(3 * i + 2)] = b.inertia;
  }
  output_evaluations_.assign(model.elements().size(), 0);
  constraint_row_owner_.resize(static_cast<std::size_t>(model.constraint_rows()));
  row_is_rotational_.resize(static_cast<std::size_t>(model.constraint_rows()));
  for (std::size_t e = 0; e < model.elements().size(); ++e) {
    const Element& el = *model.elements()[e];
    for (int r = 0; r < el.constraint_count(); ++r) {
      constraint_row_owner_[static_cast<std::size_t>(model.constraint_offset(e) + r)] = static_cast<int>(e);
      row_is_rotational_[static_cast<std::size_t>(model.constraint_offset(e) + r)] = el.constraint_row_is_rotational(r);
    }
    output_offset_.push_back(static_cast<int>(output_names_.size()));
    for (const std::string& q : el.output_names()) output_names_.push_back(el.name() + "." + q);
    root_offset_.push_back(root_count_);
    root_count_ += el.root_count();
    root_owner_.insert(root_owner_.end(), static_cast<std::size_t>(el.root_count()), static_cast<int>(e));
    std::vector<int> unknowns;
    for (int slot = 0; slot < 2; ++slot) {
      const int b = el.slot_body(slot);
      if (b == kGround) continue;
      for (int c = 0; c < 3; ++c) {
        unknowns.push_back(3 * b + c);
        unknowns.push_back(3 * model.body_count() + 3 * b + c);
      }
    }
    for (int r = 0; r < el.constraint_count(); ++r) unknowns.push_back(6 * model.body_count() + model.constraint_offset(e) + r);
    element_unknowns_.push_back(std::move(unknowns));
  }

  const std::vector<double> sizes = body_sizes(model);
  row_length_.assign(static_cast<std::size_t>(model.constraint_rows()), 1.0);
  for (std::size_t e = 0; e < model.elements().size(); ++e) {
    const Element& el = *model.elements()[e];
    double arm = 0.0;  // [length]
    for (int slot = 0; slot < 2; ++slot)
      if (el.slot_body(slot) != kGround) arm = std::max(arm, sizes[static_cast<std::size_t>(el.slot_body(slot))]);
    if (!(arm > 0.0)) arm = model.origin_free_length_scale();
    for (int r = 0; r < el.constraint_count(); ++r)
      if (el.constraint_row_is_rotational(r)) row_length_[static_cast<std::size_t>(model.constraint_offset(e) + r)] = arm;
  }

  // Dry run: learn the pattern from the same assembly code, then give every addition its slot.
  const std::vector<double> y = initial_state();
  const std::vector<double> yp(y.size(), 0.0);
  PatternRecorder recorder;
  assemble_jacobian(0.0, 1.0, y.data(), yp.data(), recorder);
  std::vector<std::pair<int, int>> unique = recorder.entries;
  std::sort(unique.begin(), unique.end());
  unique.erase(std::unique(unique.begin(), unique.end()), unique.end());
  pattern_.size = size();
  pattern_.column_start.assign(static_cast<std::size_t>(size() + 1), 0);
  pattern_.row_index.resize(unique.size());
  for (std::size_t k = 0; k < unique.size(); ++k) {
    pattern_.row_index[k] = unique[k].second;
    ++pattern_.column_start[static_cast<std::size_t>(unique[k].first + 1)];
  }
  for (int c = 0; c < size(); ++c)
    pattern_.column_start[static_cast<std::size_t>(c + 1)] += pattern_.column_start[static_cast<std::size_t>(c)];
  slots_.resize(recorder.entries.size());
  for (std::size_t k = 0; k < recorder.entries.size(); ++k) {
    const auto it = std::lower_bound(unique.begin(), unique.end(), recorder.entries[k]);
    slots_[k] = static_cast<int>(it - unique.begin());
  }
}

std::vector<double> DaeSystem::initial_state() const {
  std::vector<double> y(static_cast<std::size_t>(size()), 0.0);
  const int n = model_.body_count();
  for (int i = 0; i < n; ++i) {
    const Body& b = model_.bodies()[static_cast<std::size_t>(i)];
    y[static_cast<std::size_t>(model_.q_index(i, 0))] = b.x;
    y[static_cast<std::size_t>(model_.q_index(i, 1))] = b.y;
    y[static_cast<std::size_t>(model_.q_index(i, 2))] = b.angle;
    y[static_cast<std::size_t>(model_.v_index(i, 0))] = b.vx;
    y[static_cast<std::size_t>(model_.v_index(i, 1))] = b.vy;
    y[static_cast<std::size_t>(model_.v_index(i, 2))] = b.angular_velocity;
  }
  return y;
}

std::vector<double> DaeSystem::differential_ids() const {
  std::vector<double> id(static_cast<std::size_t>(size()), 0.0);
  std::fill(id.begin(), id.begin() + 6 * model_.body_count(), 1.0);
  return id;
}

void DaeSystem::gravity_and_load_forces(double t, const double* q, double* f) const {
  for (int i = 0; i < model_.body_count(); ++i) {
    f[3 * i] = mass_[static_cast<std::size_t>(3 * i)] * model_.gravity_x;
    f[3 * i + 1] = mass_[static_cast<std::size_t>(3 * i)] * model_.gravity_y;
    f[3 * i + 2] = 0.0;
  }
  load_forces(t, q, f);
}

void DaeSystem::load_forces(double t, const double* q, double* f) const {
  for (const Load& load : model_.loads()) {
    const std::array<double, 2> value = load.value.at(t);
    double* fb = f + 3 * load.body;
    if (load.kind == Load::Kind::Moment) {
      fb[2] += value[0];
    } else {
      const Pose<double> pose{q[3 * load.body], q[3 * load.body + 1], q[3 * load.body + 2]};
      Pose<double> generalized{};
      add_point_force(pose, load.sx, load.sy, Vec2<double>{value[0], value[1]}, generalized);
      fb[0] += generalized.x;
      fb[1] += generalized.y;
      fb[2] += generalized.theta;
    }
  }
}

namespace {
/// Power the bodies deliver to an element that applies the forces fe to them: -sum fe . v.
double power_into(const std::array<Pose<double>, 2>& fe, const ElementState<double>& s) {
  double power = 0.0;
  for (std::size_t k = 0; k < 2; ++k) power -= fe[k].x * s.v[k].x + fe[k].y * s.v[k].y + fe[k].theta * s.v[k].theta;
  return power;
}

/// fe += more, body by body.
void add_poses(std::array<Pose<double>, 2>& fe, const std::array<Pose<double>, 2>& more) {
  for (std::size_t k = 0; k < 2; ++k) {
    fe[k].x += more[k].x;
    fe[k].y += more[k].y;
    fe[k].theta += more[k].theta;
  }
}

/// An element's forces fe on its two bodies, added to the generalized forces f.
void add_to_bodies(const Element& el, const std::array<Pose<double>, 2>& fe, double* f) {
  for (int k = 0; k < 2; ++k) {
    const int b = el.slot_body(k);
    if (b == kGround) continue;
    f[3 * b] += fe[static_cast<std::size_t>(k)].x;
    f[3 * b + 1] += fe[static_cast<std::size_t>(k)].y;
    f[3 * b + 2] += fe[static_cast<std::size_t>(k)].theta;
  }
}
}  // namespace

void DaeSystem::generalized_forces(double t, const double* q, const double* v, double* f, const PenaltyRows* penalty,
                                   double* penalty_lambda, const double* lambda, const SweepExtras* extras) const {
  double* powers = extras ? extras->powers : nullptr;
  if (powers) {
    body_quadrature_rates(t, q, v, powers);
    powers[kPenaltyWork] = 0.0;
  }
  gravity_and_load_forces(t, q, f);
  // What the sweep fills beside the forces, read once (the elements' calls are opaque: read in
  // the loop, each would be loaded again for every element).
  double* const roots = extras ? extras->roots : nullptr;
  double* const all_outputs = extras ? extras->outputs : nullptr;
  const char* const output_elements = extras ? extras->output_elements : nullptr;
  const double* const y_lambda = extras ? extras->y_lambda : nullptr;
  const bool sweep = roots != nullptr || all_outputs != nullptr;  // (an element with neither is not asked for them)
  for (std::size_t e = 0; e < model_.elements().size(); ++e) {
    const Element& el = *model_.elements()[e];
    const ElementState<double> s = local_state(e, q, v);
    const int m = el.constraint_count();
    double* const outputs = output_elements == nullptr || output_elements[e] != 0 ? all_outputs : nullptr;
    if (sweep && m > 0) element_roots_and_outputs(e, t, s, y_lambda, roots, outputs);
    std::array<Pose<double>, 2> fe{};
    double* element_power = powers ? powers + kFirstElementWork + static_cast<int>(e) : nullptr;
    if (element_power) *element_power = 0.0;
    if (m == 0) {
      if (sweep)
        element_force_roots_and_outputs(e, t, s, y_lambda, fe, roots, outputs);
      else
        el.add_force(t, s, fe);
      if (element_power) *element_power = power_into(fe, s);
    } else {
      const int offset = model_.constraint_offset(e);
      double reactions[kMaxConstraintRows] = {};  // multipliers the joint's friction sees
      if (penalty != nullptr) {
        if (element_failed(e)) {
          if (penalty_lambda)
            for (int r = 0; r < m; ++r) penalty_lambda[offset + r] = 0.0;
          continue;
        }
        double phi[kMaxConstraintRows];
        double grad[kMaxConstraintRows][6];
        el.constraint_gradient(s.q, phi, grad);
        for (int r = 0; r < m; ++r) {
          const auto row = static_cast<std::size_t>(offset + r);
          double rate = 0.0;
          for (int k = 0; k < 2; ++k)
            for (int c = 0; c < 3; ++c) rate += grad[r][3 * k + c] * component(s.v[static_cast<std::size_t>(k)], c);
          reactions[r] = penalty->stiffness[row] * phi[r] + penalty->damping[row] * rate;
          if (penalty_lambda) penalty_lambda[row] = reactions[r];
          if (powers) powers[kPenaltyWork] += reactions[r] * rate;
          for (int k = 0; k < 2; ++k)
            for (int c = 0; c < 3; ++c) component(fe[static_cast<std::size_t>(k)], c) -= grad[r][3 * k + c] * reactions[r];
        }
      } else if (lambda != nullptr) {
        for (int r = 0; r < m; ++r) reactions[r] = lambda[offset + r];
      } else {
        continue;
      }
      if (el.has_joint_force() && !element_failed(e)) {
        std::array<Pose<double>, 2> friction{};
        el.add_joint_force(t, s, reactions, friction);
        if (element_power) *element_power = power_into(friction, s);
        add_poses(fe, friction);
      }
    }
    add_to_bodies(el, fe, f);
  }
}

void DaeSystem::generalized_forces_at_reactions(double t, const double* q, const double* v, const double* lambda, double* f,
                                                ForcesAtReactions& fixed) const {
  const std::size_t count = model_.elements().size();
  const int nq = body_unknowns();
  if (!fixed.ready) {
    fixed.base.resize(static_cast<std::size_t>(nq));
    gravity_and_load_forces(t, q, fixed.base.data());
    fixed.elements.assign(count, std::array<Pose<double>, 2>{});
    for (std::size_t e = 0; e < count; ++e) {
      const Element& el = *model_.elements()[e];
      if (el.constraint_count() == 0) el.add_force(t, local_state(e, q, v), fixed.elements[e]);
    }
    fixed.ready = true;
  }
  std::copy(fixed.base.begin(), fixed.base.end(), f);
  for (std::size_t e = 0; e < count; ++e) {
    const Element& el = *model_.elements()[e];
    std::array<Pose<double>, 2> fe = fixed.elements[e];
    const int m = el.constraint_count();
    if (m > 0 && el.has_joint_force() && !element_failed(e)) {
      const int offset = model_.constraint_offset(e);
      double reactions[kMaxConstraintRows] = {};
      for (int r = 0; r < m; ++r) reactions[r] = lambda[offset + r];
      std::array<Pose<double>, 2> friction{};
      el.add_joint_force(t, local_state(e, q, v), reactions, friction);
      add_poses(fe, friction);
    }
    add_to_bodies(el, fe, f);
  }
}

void DaeSystem::residual(double t, const double* y, const double* yp, double* r) const {
  const int nq = body_unknowns();
  const double* q = y;
  const double* v = y + nq;
  const double* lambda = y + 2 * nq;
  const double* mu = lambda + constraint_rows();
  double* r_q = r;
  double* r_v = r + nq;
  double* r_phi = r + 2 * nq;
  double* r_vel = r_phi + constraint_rows();

  generalized_forces(t, q, v, r_v, nullptr, nullptr, lambda);  // r_v = f for now
  for (int k = 0; k < nq; ++k) {
    r_q[k] = yp[k] - v[k];
    r_v[k] = mass_[static_cast<std::size_t>(k)] * yp[nq + k] - r_v[k];
  }
  for (std::size_t e = 0; e < model_.elements().size(); ++e) {
    const Element& el = *model_.elements()[e];
    const int m = el.constraint_count();
    if (m == 0) continue;
    const int offset = model_.constraint_offset(e);
    if (element_failed(e)) {  // rows become lambda = 0, mu = 0
      for (int row = 0; row < m; ++row) {
        r_phi[offset + row] = lambda[offset + row];
        r_vel[offset + row] = mu[offset + row];
      }
      continue;
    }
    const std::array<Pose<double>, 2> poses = gather_poses(el, q);
    double phi[kMaxConstraintRows];
    double grad[kMaxConstraintRows][6];
    el.constraint_gradient(poses, phi, grad);
    for (int row = 0; row < m; ++row) {
      const int g = offset + row;
      r_phi[g] = phi[row];
      double rate = 0.0;
      for (int k = 0; k < 2; ++k) {
        const int b = el.slot_body(k);
        if (b == kGround) continue;
        for (int c = 0; c < 3; ++c) {
          const double gv = grad[row][3 * k + c];
          r_q[3 * b + c] += gv * mu[g];
          r_v[3 * b + c] += gv * lambda[g];
          rate += gv * v[3 * b + c];
        }
      }
      r_vel[g] = rate;
    }
  }
}

template <class Sink>
void DaeSystem::assemble_jacobian(double t, double cj, const double* y, const double* yp, Sink& sink) const {
  (void)yp;
  const int nq = body_unknowns();
  const int n = model_.body_count();
  const double* q = y;
  const double* v = y + nq;
  const double* lambda = y + 2 * nq;
  const double* mu = lambda + constraint_rows();

  // Bodies: r_q = q' - v,  r_v = M v' - f
  for (int k = 0; k < nq; ++k) {
    sink.add(k, k, cj);
    sink.add(k, nq + k, -1.0);
    sink.add(nq + k, nq + k, cj * mass_[static_cast<std::size_t>(k)]);
  }
  // Loads: the moment of a force at an offset point depends on theta.
  for (const Load& load : model_.loads()) {
    if (load.kind != Load::Kind::Force) continue;
    const std::array<double, 2> value = load.value.at(t);
    const double theta = q[3 * load.body + 2];
    const Vec2<double> arm = rotate(theta, load.sx, load.sy);
    // M = arm x F,  d arm / d theta = perp(arm) = (-arm_y, arm_x)
    const double dmoment = -arm.y * value[1] - arm.x * value[0];
    sink.add(nq + 3 * load.body + 2, 3 * load.body + 2, -dmoment);
  }
  (void)n;
  for (std::size_t e = 0; e < model_.elements().size(); ++e) {
    const Element& el = *model_.elements()[e];
    const int m = el.constraint_count();
    sink.begin_element(static_cast<int>(e));
    const ElementState<double> s = local_state(e, q, v);
    if (m == 0) {
      std::array<Pose<double>, 2> f{};
      ForceBlock df_dq{}, df_dv{};
      el.add_force_jacobian(t, s, f, df_dq, df_dv);
      for_each_body_pair(el, [&](int row, int col, std::size_t li, std::size_t lj) {
        sink.add(nq + row, col, -df_dq[li][lj]);
        sink.add(nq + row, nq + col, -df_dv[li][lj]);
      });
      continue;
    }
    const int offset = model_.constraint_offset(e);
    double phi[kMaxConstraintRows];
    double grad[kMaxConstraintRows][6];
    double hess[kMaxConstraintRows][6][6];
    el.constraint_hessian(s.q, phi, grad, hess);
    // A failed constraint writes the same entries (the pattern never changes) as zeros,
    // and ones on its lambda and mu diagonals.
    const double active = element_failed(e) ? 0.0 : 1.0;
    if (element_failed(e)) {
      for (auto& row : grad)
        for (double& value : row) value = 0.0;
      for (auto& row : hess)
        for (auto& line : row)
          for (double& value : line) value = 0.0;
    }
    double local_v[6];
    flatten_rates(s, local_v);
    // Second-derivative blocks: d(G^T mu)/dq and d(G^T lambda)/dq.
    for_each_body_pair(el, [&](int row_q, int col_q, std::size_t li, std::size_t lj) {
      double with_mu = 0.0, with_lambda = 0.0;
      for (int row = 0; row < m; ++row) {
        const double h = hess[row][li][lj];
        with_mu += mu[offset + row] * h;
        with_lambda += lambda[offset + row] * h;
      }
      sink.add(row_q, col_q, with_mu);
      sink.add(nq + row_q, col_q, with_lambda);
    });
    for (int row = 0; row < m; ++row) {
      const int g = offset + row;
      const int row_phi = model_.lambda_index(g);
      const int row_vel = model_.mu_index(g);
      for (int a = 0; a < 2; ++a) {
        const int ba = el.slot_body(a);
        if (ba == kGround) continue;
        for (int i = 0; i < 3; ++i) {
          const double gv = grad[row][3 * a + i];
          double dvel_dq = 0.0;  // d(G v)/dq = sum_j H[i][j] v_j (H symmetric)
          for (int j = 0; j < 6; ++j) dvel_dq += hess[row][3 * a + i][j] * local_v[j];
          sink.add(3 * ba + i, model_.mu_index(g), gv);          // r_q: G^T mu
          sink.add(nq + 3 * ba + i, model_.lambda_index(g), gv); // r_v: G^T lambda
          sink.add(row_phi, 3 * ba + i, gv);                     // r_phi: G
          sink.add(row_vel, 3 * ba + i, dvel_dq);                // r_vel: dG v / dq
          sink.add(row_vel, nq + 3 * ba + i, gv);                // r_vel: G
        }
      }
      // Diagonal slots of a constraint that fails (its rows become lambda = 0, mu = 0).
      sink.add(row_phi, model_.lambda_index(g), 1.0 - active);
      sink.add(row_vel, model_.mu_index(g), 1.0 - active);
    }
    if (!el.has_joint_force()) continue;
    // Friction: r_v -= f(q, v, lambda).
    std::array<Pose<double>, 2> f{};
    ForceBlock df_dq{}, df_dv{};
    double df_dlambda[6][kMaxConstraintRows] = {};
    if (!element_failed(e)) el.add_joint_force_jacobian(t, s, lambda + offset, f, df_dq, df_dv, df_dlambda);
    for_each_body_pair(el, [&](int row, int col, std::size_t li, std::size_t lj) {
      sink.add(nq + row, col, -df_dq[li][lj]);
      sink.add(nq + row, nq + col, -df_dv[li][lj]);
    });
    for (int a = 0; a < 2; ++a) {
      const int ba = el.slot_body(a);
      if (ba == kGround) continue;
      for (int i = 0; i < 3; ++i)
        for (int row = 0; row < m; ++row)
          sink.add(nq + 3 * ba + i, model_.lambda_index(offset + row), -df_dlambda[static_cast<std::size_t>(3 * a + i)][row]);
    }
  }
}

void DaeSystem::jacobian(double t, double cj, const double* y, const double* yp, double* values) const {
  std::fill(values, values + pattern_.nonzeros(), 0.0);
  SlotWriter writer{slots_.data(), values};
  assemble_jacobian(t, cj, y, yp, writer);
  RAILCRASH_DEMAND(writer.slot == slots_.data() + slots_.size());
}

void DaeSystem::add_rate_jacobian(double factor, double* values) const {
  // assemble_jacobian's first 3 nq additions: (k, k) cj, (k, nq + k) -1, (nq + k, nq + k) cj M_k.
  const int nq = body_unknowns();
  for (int k = 0; k < nq; ++k) {
    values[slots_[static_cast<std::size_t>(3 * k)]] += factor;
    values[slots_[static_cast<std::size_t>(3 * k + 2)]] += factor * mass_[static_cast<std::size_t>(k)];
  }
}

void DaeSystem::force_jacobian(double t, const double* q, const double* v, const PenaltyRows* penalty,
                               std::vector<Triplet>& df_dq, std::vector<Triplet>& df_dv, bool stiffest) const {
  df_dq.clear();
  df_dv.clear();
  for (const Load& load : model_.loads()) {
    if (load.kind != Load::Kind::Force) continue;
    const std::array<double, 2> value = load.value.at(t);
    const Vec2<double> arm = rotate(q[3 * load.body + 2], load.sx, load.sy);
    df_dq.push_back({3 * load.body + 2, 3 * load.body + 2, -arm.y * value[1] - arm.x * value[0]});
  }
  for (std::size_t e = 0; e < model_.elements().size(); ++e) {
    const Element& el = *model_.elements()[e];
    const int m = el.constraint_count();
    const ElementState<double> s = local_state(e, q, v);
    ForceBlock dq{}, dv{};
    if (m == 0) {
      std::array<Pose<double>, 2> f{};
      if (stiffest)
        el.stiffest_force_jacobian(t, s, dq, dv);
      else
        el.add_force_jacobian(t, s, f, dq, dv);
    } else {
      if (!penalty || element_failed(e)) continue;
      // f = -G^T (k Phi + c G v): df/dq ~ -k G^T G (curvature terms of the multiplier dropped:
      // this Jacobian only feeds the stability estimate), df/dv = -c G^T G.
      double phi[kMaxConstraintRows];
      double grad[kMaxConstraintRows][6];
      el.constraint_gradient(s.q, phi, grad);
      const int offset = model_.constraint_offset(e);
      for (int row = 0; row < m; ++row) {
        const auto g = static_cast<std::size_t>(offset + row);
        for (std::size_t i = 0; i < 6; ++i)
          for (std::size_t j = 0; j < 6; ++j) {
            dq[i][j] -= penalty->stiffness[g] * grad[row][i] * grad[row][j];
            dv[i][j] -= penalty->damping[g] * grad[row][i] * grad[row][j];
          }
      }
    }
    for_each_body_pair(el, [&](int row, int col, std::size_t li, std::size_t lj) {
      df_dq.push_back({row, col, dq[li][lj]});
      df_dv.push_back({row, col, dv[li][lj]});
    });
  }
}

void DaeSystem::constraints(const double* q, double* phi, std::vector<Triplet>* gradient) const {
  if (gradient) gradient->clear();
  for (std::size_t e = 0; e < model_.elements().size(); ++e) {
    const Element& el = *model_.elements()[e];
    const int m = el.constraint_count();
    if (m == 0) continue;
    const int offset = model_.constraint_offset(e);
    if (element_failed(e)) {  // no equation left: Phi = 0, no gradient
      for (int row = 0; row < m; ++row) phi[offset + row] = 0.0;
      continue;
    }
    const std::array<Pose<double>, 2> poses = gather_poses(el, q);
    double grad[kMaxConstraintRows][6];
    el.constraint_gradient(poses, phi + offset, grad);
    if (!gradient) continue;
    for (int row = 0; row < m; ++row)
      for (int k = 0; k < 2; ++k) {
        const int b = el.slot_body(k);
        if (b == kGround) continue;
        for (int c = 0; c < 3; ++c) gradient->push_back({offset + row, 3 * b + c, grad[row][3 * k + c]});
      }
  }
}

void DaeSystem::constraint_acceleration_bias(const double* q, const double* v, double* gamma) const {
  for (std::size_t e = 0; e < model_.elements().size(); ++e) {
    const Element& el = *model_.elements()[e];
    const int m = el.constraint_count();
    if (m == 0) continue;
    if (element_failed(e)) {
      for (int row = 0; row < m; ++row) gamma[model_.constraint_offset(e) + row] = 0.0;
      continue;
    }
    const ElementState<double> s = local_state(e, q, v);
    double phi[kMaxConstraintRows];
    double grad[kMaxConstraintRows][6];
    double hess[kMaxConstraintRows][6][6];
    el.constraint_hessian(s.q, phi, grad, hess);
    double local_v[6];
    flatten_rates(s, local_v);
    for (int row = 0; row < m; ++row) {
      double sum = 0.0;
      for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 6; ++j) sum += local_v[i] * hess[row][i][j] * local_v[j];
      gamma[model_.constraint_offset(e) + row] = sum;
    }
  }
}

double DaeSystem::constraint_residual(const double* q) const {
  std::vector<double> phi;
  return constraint_residual(q, phi);
}

double DaeSystem::constraint_residual(const double* q, std::vector<double>& phi) const {
  phi.assign(static_cast<std::size_t>(constraint_rows()), 0.0);  // a failed element's rows stay 0
  // The values alone (Element::constraint): constraints() would also differentiate every row.
  for (std::size_t e = 0; e < model_.elements().size(); ++e) {
    const Element& el = *model_.elements()[e];
    if (el.constraint_count() == 0 || element_failed(e)) continue;
    el.constraint(gather_poses(el, q), phi.data() + model_.constraint_offset(e));
  }
  double worst = 0.0;
  for (int row = 0; row < constraint_rows(); ++row) {
    worst = std::max(worst, std::abs(phi[static_cast<std::size_t>(row)]) * constraint_row_length(row));
  }
  return worst;
}

const Element& DaeSystem::constraint_owner(int row) const {
  return *model_.elements()[static_cast<std::size_t>(constraint_row_owner_[static_cast<std::size_t>(row)])];
}

std::string DaeSystem::element_label(int e, const char* noun) const {
  const Element& el = *model_.elements()[static_cast<std::size_t>(e)];
  return el.where().prefix() + noun + " '" + el.name() + "' (" + el.type() + ")";
}

bool DaeSystem::constraint_element_failed(int e) const {
  const auto index = static_cast<std::size_t>(e);
  return model_.elements()[index]->constraint_count() > 0 && element_failed(index);
}

std::vector<double> DaeSystem::body_angle_lengths() const {
  const double length = model_.length_scale();
  std::vector<double> size = body_sizes(model_);
  for (double& r : size) r = r > 0.0 ? std::min(std::max(r, 1e-3 * length), length) : length;
  return size;
}

std::vector<double> DaeSystem::constraint_row_inverse_mass_bounds() const {
  // (Taken at the start only, (G M^-1 G^T)_rr would let a penalty sized from it outrun the
  // step once the bodies turn.)
  std::vector<double> inverse_effective_mass(static_cast<std::size_t>(constraint_rows()), 0.0);
  for (std::size_t e = 0; e < model_.elements().size(); ++e) {
    const Element& el = *model_.elements()[e];
    for (int row = 0; row < el.constraint_count(); ++row) {
      double inverse = 0.0;
      for (int slot = 0; slot < 2; ++slot) {
        const int b = el.slot_body(slot);
        if (b == kGround) continue;
        const Body& body = model_.bodies()[static_cast<std::size_t>(b)];
        double arm = 0.0;
        for (std::size_t p = 0; p < el.points().size(); ++p)
          if (el.point_slot(static_cast<int>(p)) == slot) arm = std::max(arm, std::hypot(el.points()[p].sx, el.points()[p].sy));
        inverse += el.constraint_row_is_rotational(row) ? 1.0 / body.inertia : 1.0 / body.mass + arm * arm / body.inertia;
      }
      inverse_effective_mass[static_cast<std::size_t>(model_.constraint_offset(e) + row)] = inverse;
    }
  }
  return inverse_effective_mass;
}

std::string DaeSystem::unknown_name(int k) const {
  const int nq = body_unknowns();
  const int m = constraint_rows();
  if (k < 2 * nq) {
    // Positions x, y, theta of every body, then their velocities.
    static const std::array<const char*, 6> kCoordinate = {"x", "y", "theta", "vx", "vy", "omega"};
    const int coordinate = (k < nq ? 0 : 3) + k % 3;
    const Body& body = model_.bodies()[static_cast<std::size_t>((k % nq) / 3)];
    return body.where.prefix() + "body '" + body.name + "' " + kCoordinate[static_cast<std::size_t>(coordinate)];
  }
  const int row = (k - 2 * nq) % m;
  const Element& owner = constraint_owner(row);
  const int local = row - model_.constraint_offset(static_cast<std::size_t>(constraint_row_owner_[static_cast<std::size_t>(row)]));
  return owner.where().prefix() + "element '" + owner.name() + "' (" + owner.type() + ") " +
         (k < 2 * nq + m ? "multiplier" : "velocity multiplier") + " of its constraint row " + std::to_string(local);
}

std::string DaeSystem::non_finite_source(double t, const double* y, const double* yp) const {
  const int n = size();
  const int nq = body_unknowns();
  std::ostringstream msg;
  for (int k = 0; k < n; ++k) {
    if (!std::isfinite(y[k])) return (msg << unknown_name(k) << " is " << y[k], msg.str());
    if (!std::isfinite(yp[k])) return (msg << "the rate of " << unknown_name(k) << " is " << yp[k], msg.str());
  }
  const auto element_text = [&](std::size_t e) {
    const Element& el = *model_.elements()[e];
    return el.where().prefix() + "element '" + el.name() + "' (" + el.type() + ")";
  };
  // Each element alone: its forces and power, its constraint rows and their gradients.
  for (std::size_t e = 0; e < model_.elements().size(); ++e) {
    const ElementLoad load = element_load(static_cast<int>(e), t, y);
    bool finite = std::isfinite(load.power);
    for (const Pose<double>& f : load.force) finite = finite && std::isfinite(f.x) && std::isfinite(f.y) && std::isfinite(f.theta);
    if (!finite) return element_text(e) + ": its force or power is not finite";
  }
  std::vector<double> phi(static_cast<std::size_t>(constraint_rows()));
  std::vector<Triplet> gradient;
  constraints(y, phi.data(), &gradient);
  for (int r = 0; r < constraint_rows(); ++r)
    if (!std::isfinite(phi[static_cast<std::size_t>(r)]))
      return element_text(static_cast<std::size_t>(constraint_row_owner_[static_cast<std::size_t>(r)])) +
             ": its constraint equation is not finite";
  for (const Triplet& g : gradient)
    if (!std::isfinite(g.value))
      return element_text(static_cast<std::size_t>(constraint_row_owner_[static_cast<std::size_t>(g.row)])) +
             ": its constraint gradient is not finite";
  // The Jacobian, element by element (cj = 1: the mass terms count).
  NonFiniteFinder finder;
  assemble_jacobian(t, 1.0, y, yp, finder);
  if (finder.found) {
    if (finder.found_owner >= 0)
      return (msg << element_text(static_cast<std::size_t>(finder.found_owner)) << ": its derivative with respect to "
                  << unknown_name(finder.col) << " is " << finder.value,
              msg.str());
    return (msg << "the mass matrix or a load acting on " << unknown_name(finder.row % nq) << " is " << finder.value, msg.str());
  }
  std::vector<double> r(static_cast<std::size_t>(n));
  residual(t, y, yp, r.data());
  for (int k = 0; k < n; ++k)
    if (!std::isfinite(r[static_cast<std::size_t>(k)]))
      return (msg << "the equation of " << unknown_name(k) << " is " << r[static_cast<std::size_t>(k)]
                  << " (a sum of finite terms that overflows: check the masses, inertias and stiffnesses there)",
              msg.str());
  return "";
}

double DaeSystem::kinetic_energy(const double* v) const {
  double ke = 0.0;
  for (int k = 0; k < body_unknowns(); ++k) ke += 0.5 * mass_[static_cast<std::size_t>(k)] * v[k] * v[k];
  return ke;
}

double DaeSystem::gravity_potential(const double* q) const {
  double pe = 0.0;
  for (int i = 0; i < model_.body_count(); ++i)
    pe -= mass_[static_cast<std::size_t>(3 * i)] * (model_.gravity_x * q[3 * i] + model_.gravity_y * q[3 * i + 1]);
  return pe;
}

void DaeSystem::body_quadrature_rates(double t, const double* q, const double* v, double* rates) const {
  rates[kKineticIntegral] = kinetic_energy(v);
  // Power of the applied loads.
  double load_power = 0.0;
  for (const Load& load : model_.loads()) {
    const std::array<double, 2> value = load.value.at(t);
    const double* vb = v + 3 * load.body;
    if (load.kind == Load::Kind::Moment) {
      load_power += value[0] * vb[2];
    } else {
      const Pose<double> pose{q[3 * load.body], q[3 * load.body + 1], q[3 * load.body + 2]};
      const Pose<double> rate{vb[0], vb[1], vb[2]};
      const Vec2<double> point_rate = point_velocity(pose, rate, load.sx, load.sy);
      load_power += value[0] * point_rate.x + value[1] * point_rate.y;
    }
  }
  rates[kLoadWork] = load_power;
}

void DaeSystem::quadrature_rates(double t, const double* y, double* rates, const double* penalty_lambda, double* g,
                                 double* outputs) const {
  const int nq = body_unknowns();
  const double* q = y;
  const double* v = y + nq;
  body_quadrature_rates(t, q, v, rates);
  // Power delivered to each force element: -sum f_e . v over its bodies.
  double penalty_power = 0.0;
  for (std::size_t e = 0; e < model_.elements().size(); ++e) {
    const Element& el = *model_.elements()[e];
    double power = 0.0;
    const ElementState<double> s = local_state(e, q, v);
    const bool sweep = g != nullptr || outputs != nullptr;  // roots and outputs as roots() gives them
    if (sweep && el.constraint_count() > 0) element_roots_and_outputs(e, t, s, y + 2 * nq, g, outputs);
    if (el.constraint_count() == 0) {
      std::array<Pose<double>, 2> fe{};
      if (sweep)
        element_force_roots_and_outputs(e, t, s, y + 2 * nq, fe, g, outputs);
      else
        el.add_force(t, s, fe);
      power = power_into(fe, s);
    } else if (el.has_joint_force() && !element_failed(e)) {
      // Friction of a joint: its reactions are the multipliers (ida) or penalty forces (euler).
      const double* reactions = (penalty_lambda ? penalty_lambda : y + 2 * nq) + model_.constraint_offset(e);
      std::array<Pose<double>, 2> fe{};
      el.add_joint_force(t, s, reactions, fe);
      power = power_into(fe, s);
    }
    if (el.constraint_count() > 0 && penalty_lambda) {
      // Penalty force -G^T lambda does power -lambda . (G v) on the bodies.
      double phi[kMaxConstraintRows];
      double grad[kMaxConstraintRows][6];
      el.constraint_gradient(s.q, phi, grad);
      const int offset = model_.constraint_offset(e);
      for (int row = 0; row < el.constraint_count(); ++row) {
        double rate = 0.0;
        for (std::size_t k = 0; k < 2; ++k)
          rate += grad[row][3 * k] * s.v[k].x + grad[row][3 * k + 1] * s.v[k].y + grad[row][3 * k + 2] * s.v[k].theta;
        penalty_power += penalty_lambda[offset + row] * rate;
      }
    }
    rates[kFirstElementWork + static_cast<int>(e)] = power;
  }
  rates[kPenaltyWork] = penalty_power;
}

EnergyState DaeSystem::energy(const double* y, const double* quadratures, const PenaltyRows* penalty) const {
  const int nq = body_unknowns();
  EnergyState s;
  s.kinetic = kinetic_energy(y + nq);
  s.gravity = gravity_potential(y);
  const std::size_t count = model_.elements().size();
  s.element_elastic.resize(count);
  s.element_work_done.resize(count);
  s.element_dissipates.resize(count);
  for (std::size_t e = 0; e < count; ++e) {
    const StoredEnergy stored = element_stored_energy(e, y);
    s.element_elastic[e] = stored.stored;
    s.element_dissipates[e] = stored.dissipates;
    s.element_work_done[e] = quadratures[kFirstElementWork + static_cast<int>(e)];
    s.elastic += stored.stored;
  }
  if (penalty && constraint_rows() > 0) {
    std::vector<double> phi(static_cast<std::size_t>(constraint_rows()));
    constraints(y, phi.data(), nullptr);
    for (std::size_t row = 0; row < phi.size(); ++row)
      s.penalty_elastic += 0.5 * penalty->stiffness[row] * phi[row] * phi[row];
    s.elastic += s.penalty_elastic;
  }
  s.load_work = quadratures[kLoadWork];
  s.penalty_work = quadratures[kPenaltyWork];
  s.element_work = s.penalty_work;
  for (std::size_t e = 0; e < count; ++e) s.element_work += s.element_work_done[e];
  return s;
}

DaeSystem::WorkBalance DaeSystem::work_balance(const EnergyState& start, const double* y, const double* quadratures) const {
  const double kinetic = kinetic_energy(y + body_unknowns());
  const double gravity = gravity_potential(y) - start.gravity;
  const double loads = quadratures[kLoadWork] - start.load_work;
  double work = -start.element_work;  // penalties', then each element's
  for (int k = kPenaltyWork; k < kFirstElementWork + element_count(); ++k) work += quadratures[k];
  WorkBalance b;
  b.lost = start.kinetic + loads - (kinetic + gravity + work);
  b.turned_over = std::max(std::abs(start.kinetic + start.elastic), kinetic + std::abs(gravity) + std::abs(work) + std::abs(loads));
  return b;
}

double DaeSystem::element_potential_energy(std::size_t e, const double* y) const {
  return model_.elements()[e]->potential_energy(local_state(e, y, y + body_unknowns()));
}

DaeSystem::StoredEnergy DaeSystem::element_stored_energy(std::size_t e, const double* y) const {
  const Element& el = *model_.elements()[e];
  const ElementState<double> s = local_state(e, y, y + body_unknowns());
  return {el.potential_energy(s), !el.conservative(s)};
}

void DaeSystem::roots(double t, const double* y, double* g, double* outputs) const {
  const int nq = body_unknowns();
  const double* lambda = y + 2 * nq;
  for (std::size_t e = 0; e < model_.elements().size(); ++e) {
    const Element& el = *model_.elements()[e];
    const bool has_roots = el.root_count() > 0;
    const bool has_outputs = outputs != nullptr && output_offset_[e] < output_end(e);
    if (!has_roots && !has_outputs) continue;
    element_roots_and_outputs(e, t, local_state(e, y, y + nq), lambda, g, outputs);
  }
}

DaeSystem::ElementSlices DaeSystem::element_slices(std::size_t e, const double* lambda, double* g, double* outputs) const {
  const Element& el = *model_.elements()[e];
  ElementSlices slices;
  slices.lambda = el.constraint_count() > 0 ? lambda + model_.constraint_offset(e) : nullptr;
  slices.g = g != nullptr && el.root_count() > 0 ? g + root_offset_[e] : nullptr;
  slices.outputs = outputs != nullptr && output_offset_[e] < output_end(e) ? outputs + output_offset_[e] : nullptr;
  if (slices.outputs != nullptr) ++output_evaluations_[e];
  return slices;
}

void DaeSystem::element_roots_and_outputs(std::size_t e, double t, const ElementState<double>& s, const double* lambda,
                                          double* g, double* outputs) const {
  const ElementSlices slices = element_slices(e, lambda, g, outputs);
  if (slices.g != nullptr || slices.outputs != nullptr)
    model_.elements()[e]->roots_and_outputs(t, s, slices.lambda, slices.g, slices.outputs);
}

void DaeSystem::element_force_roots_and_outputs(std::size_t e, double t, const ElementState<double>& s, const double* lambda,
                                                std::array<Pose<double>, 2>& f, double* g, double* outputs) const {
  const ElementSlices slices = element_slices(e, lambda, g, outputs);
  model_.elements()[e]->force_roots_and_outputs(t, s, slices.lambda, f, slices.g, slices.outputs);
}

void DaeSystem::element_roots(int e, double t, const double* y, double* g) const {
  const Element& el = *model_.elements()[static_cast<std::size_t>(e)];
  const int nq = body_unknowns();
  const double* element_lambda =
      el.constraint_count() > 0 ? y + 2 * nq + model_.constraint_offset(static_cast<std::size_t>(e)) : nullptr;
  el.roots(t, local_state(static_cast<std::size_t>(e), y, y + nq), element_lambda, g);
}

const double* DaeSystem::element_multipliers(int e, const double* y) const {
  const auto index = static_cast<std::size_t>(e);
  return model_.elements()[index]->constraint_count() > 0 ? y + 2 * body_unknowns() + model_.constraint_offset(index) : nullptr;
}

DaeSystem::ElementLoad DaeSystem::element_load(int e, double t, const double* y) const {
  const Element& el = *model_.elements()[static_cast<std::size_t>(e)];
  const int nq = body_unknowns();
  const ElementState<double> s = local_state(static_cast<std::size_t>(e), y, y + nq);
  ElementLoad load;
  load.body = {el.slot_body(0), el.slot_body(1)};
  if (el.constraint_count() == 0) {
    el.add_force(t, s, load.force);
  } else if (el.has_joint_force() && !element_failed(e)) {
    el.add_joint_force(t, s, y + 2 * nq + model_.constraint_offset(static_cast<std::size_t>(e)), load.force);
  }
  load.power = power_into(load.force, s);
  return load;
}

bool DaeSystem::boundary_roots_leaving(double t, const double* y, const double* yp, double t_end, std::vector<int>& direction) const {
  if (root_count_ == 0) return false;
  std::vector<double> g(static_cast<std::size_t>(root_count_)), ahead(g.size());
  roots(t, y, g.data());
  // Second-order Taylor step (q + h v + h^2 a / 2, v + h a): a body at rest on a boundary
  // leaves it through its acceleration alone. h is small against the run's time scale but
  // large enough for h^2 a / 2 to survive round-off in q.
  const double h = 1e-6 * std::min(1.0, t_end);
  const int nq = body_unknowns();
  std::vector<double> y_ahead(y, y + size());
  for (int k = 0; k < nq; ++k) {
    y_ahead[static_cast<std::size_t>(k)] += h * yp[k] + 0.5 * h * h * yp[nq + k];
    y_ahead[static_cast<std::size_t>(nq + k)] += h * yp[nq + k];
  }
  roots(t + h, y_ahead.data(), ahead.data());
  direction.assign(g.size(), 0);
  bool any = false;
  for (std::size_t k = 0; k < g.size(); ++k)
    if (g[k] < 0.0 || ahead[k] < 0.0) {
      direction[k] = -1;
      any = true;
    }
  return any;
}

ElementState<double> DaeSystem::local_state(std::size_t e, const double* q, const double* v) const {
  return gather_state(*model_.elements()[e], q, v, modes_.of(e),
                      [this](int b, double theta) -> const Rotation<double>& { return body_rotation(b, theta); });
}

const Rotation<double>& DaeSystem::body_rotation(int b, double theta) const {
  const auto i = static_cast<std::size_t>(b);
  // Exact comparison on purpose: a different angle, however close, gets its own cos and sin.
  if (!(rotation_angle_[i] == theta)) {
    rotation_[i] = rotation_of(theta);
    rotation_angle_[i] = theta;
  }
  return rotation_[i];
}

int DaeSystem::output_end(std::size_t e) const {
  return e + 1 < output_offset_.size() ? output_offset_[e + 1] : static_cast<int>(output_names_.size());
}

bool DaeSystem::element_failed(std::size_t e) const { return model_.elements()[e]->failed(modes_.of(e)); }

void DaeSystem::outputs(const double* y, const double* lambda, double* out) const {
  for (std::size_t e = 0; e < model_.elements().size(); ++e) element_outputs(static_cast<int>(e), y, lambda, out);
}

void DaeSystem::element_outputs(int e, const double* y, const double* lambda, double* out) const {
  const auto k = static_cast<std::size_t>(e);
  const int first = output_offset_[k];
  if (first == output_end(k)) return;
  ++output_evaluations_[k];
  const Element& el = *model_.elements()[k];
  const double* element_lambda = el.constraint_count() > 0 ? lambda + model_.constraint_offset(k) : nullptr;
  el.outputs(local_state(k, y, y + body_unknowns()), element_lambda, out + first);
}

}  // namespace railcrash
