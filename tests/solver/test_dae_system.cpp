#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "railcrash/model/model_io.hpp"
#include "railcrash/results/run_files.hpp"
#include "support.hpp"

using namespace railcrash;

TEST_CASE("slider-crank Jacobian matches central differences at random states", "[dae]") {
  const Model model = load_model(std::string(RAILCRASH_SOURCE_DIR) + "/verification/cases/slider_crank.yaml").model;
  DaeSystem system(model);
  std::mt19937 rng(7);
  for (int trial = 0; trial < 5; ++trial) {
    const std::vector<double> y = testing::random_state(system, rng);
    const std::vector<double> yp = testing::random_state(system, rng);
    double outside = 0.0;
    const double cj = 10.0 * (trial + 1);
    CHECK(testing::jacobian_error(system, 0.3, cj, y, yp, &outside) < 1e-6);
    CHECK(outside == 0.0);
  }
}

TEST_CASE("a non-finite law is traced to the element or body it comes from, with file and line", "[dae][faults]") {
  // A spring of stiffness 1e308 stretched by 10: its force 1e309 overflows to inf.
  const Model model = testing::model_from_text(
      "railcrash: 1\nname: overflow\nunits: SI\ngravity: [0, 0]\nbodies:\n"
      "  - {name: bob, mass: 2, inertia: 0.1, position: [11, 0]}\nelements:\n"
      "  - {name: soft, type: linear_spring, stiffness: 1, free_length: 1, points: [{body: ground, at: [0, 0]}, {body: bob, at: [0, 0]}]}\n"
      "  - {name: hard, type: linear_spring, stiffness: 1.0e308, free_length: 1, points: [{body: ground, at: [0, 0]}, {body: bob, at: [0, 0]}]}\n"
      "simulation: {t_end: 1}\n");
  DaeSystem system(model);
  std::vector<double> y = system.initial_state();
  std::vector<double> yp(y.size(), 0.0);
  CHECK_THAT(system.non_finite_source(0.0, y.data(), yp.data()),
             Catch::Contains(":9: element 'hard' (linear_spring): its force or power is not finite"));
  // A non-finite unknown is named before any element: body, coordinate, file and line.
  y[4] = std::nan("");
  CHECK_THAT(system.non_finite_source(0.0, y.data(), yp.data()), Catch::Contains(":6: body 'bob' vy is nan"));
  y[4] = 0.0;
  yp[2] = INFINITY;
  CHECK_THAT(system.non_finite_source(0.0, y.data(), yp.data()), Catch::Contains("the rate of ") && Catch::Contains("body 'bob' theta is inf"));
  // Within range, nothing to report.
  const Model tame = testing::model_from_text(
      "railcrash: 1\nname: tame\nunits: SI\ngravity: [0, 0]\nbodies:\n  - {name: bob, mass: 2, inertia: 0.1, position: [11, 0]}\n"
      "elements:\n  - {name: soft, type: linear_spring, stiffness: 1, free_length: 1, points: [{body: ground, at: [0, 0]}, {body: bob, at: [0, 0]}]}\n"
      "simulation: {t_end: 1}\n");
  DaeSystem tame_system(tame);
  const std::vector<double> y_tame = tame_system.initial_state();
  const std::vector<double> yp_tame(y_tame.size(), 0.0);
  CHECK(tame_system.non_finite_source(0.0, y_tame.data(), yp_tame.data()).empty());
}

TEST_CASE("the quadratures' sweep gives the roots and outputs of roots() bit for bit, and the same rates", "[dae]") {
  // IdaIntegrator takes a step's roots and outputs from this sweep (QuadratureSweep): any
  // difference from roots() would change where events are found.
  const Model model = load_model(std::string(RAILCRASH_SOURCE_DIR) + "/models/report/final_two_car.yaml").model;
  DaeSystem system(model);
  REQUIRE(system.root_count() > 0);
  REQUIRE(!system.output_names().empty());
  std::mt19937 rng(11);
  for (int trial = 0; trial < 5; ++trial) {
    const std::vector<double> y = testing::random_state(system, rng, 0.05 * (trial + 1));
    const double t = 0.01 * trial;
    const auto nquad = static_cast<std::size_t>(system.quadrature_count());
    std::vector<double> rates(nquad), rates_fused(nquad);
    std::vector<double> g(static_cast<std::size_t>(system.root_count())), g_fused(g.size());
    std::vector<double> outputs(system.output_names().size()), outputs_fused(outputs.size());
    system.quadrature_rates(t, y.data(), rates.data());
    system.roots(t, y.data(), g.data(), outputs.data());
    system.quadrature_rates(t, y.data(), rates_fused.data(), nullptr, g_fused.data(), outputs_fused.data());
    CHECK(std::memcmp(rates.data(), rates_fused.data(), sizeof(double) * nquad) == 0);
    CHECK(std::memcmp(g.data(), g_fused.data(), sizeof(double) * g.size()) == 0);
    CHECK(std::memcmp(outputs.data(), outputs_fused.data(), sizeof(double) * outputs.size()) == 0);
    // Not a vacuous comparison: the state reaches the elements' roots and outputs.
    CHECK(std::count_if(g.begin(), g.end(), [](double v) { return v != 0.0; }) > 0);
    CHECK(std::count_if(outputs.begin(), outputs.end(), [](double v) { return v != 0.0; }) > 0);
  }
}

TEST_CASE("the forces at new reactions equal generalized_forces bit for bit, with only the joints' friction evaluated again",
          "[dae]") {
  // consistent_rates iterates on the reactions that the joints' friction depends on; it keeps the
  // forces that do not depend on them (DaeSystem::ForcesAtReactions). A restart's rates, and so
  // every run with joint friction, must not move by a bit.
  const Model model = load_model(std::string(RAILCRASH_SOURCE_DIR) + "/models/report/final_two_car.yaml").model;
  DaeSystem system(model);
  const int nq = system.body_unknowns();
  const int m = system.constraint_rows();
  REQUIRE(m > 0);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> reaction(-2e5, 2e5);  // [force]
  for (int trial = 0; trial < 3; ++trial) {
    std::vector<double> y = testing::random_state(system, rng, 0.05 * (trial + 1));
    const double t = 0.01 * trial;
    DaeSystem::ForcesAtReactions fixed;
    std::vector<double> expected(static_cast<std::size_t>(nq)), got(expected.size()), without_friction(expected.size());
    system.generalized_forces(t, y.data(), y.data() + nq, without_friction.data());
    for (int pass = 0; pass < 4; ++pass) {
      for (int r = 0; r < m; ++r) y[static_cast<std::size_t>(2 * nq + r)] = reaction(rng);
      system.generalized_forces(t, y.data(), y.data() + nq, expected.data(), nullptr, nullptr, y.data() + 2 * nq);
      system.generalized_forces_at_reactions(t, y.data(), y.data() + nq, y.data() + 2 * nq, got.data(), fixed);
      CHECK(fixed.ready);
      CHECK(std::memcmp(expected.data(), got.data(), sizeof(double) * expected.size()) == 0);
      // Not vacuous: the reactions reach the friction of some joint.
      CHECK(expected != without_friction);
    }
  }
}

namespace {

/// energy.csv's row at the end of a run, computed as the run folder's writer computes it:
/// the first sample at the start state (quadratures zero), the second at the run's end.
std::vector<double> energy_row(DaeSystem& system, const RunOutcome& o, std::vector<std::string>& columns) {
  EnergyWriter writer(system);
  const std::vector<double> start = system.initial_state();
  const std::vector<double> no_work(static_cast<std::size_t>(system.quadrature_count()), 0.0);
  ModeTracker modes(system);
  const ElementStates::Snapshot final_modes = modes.snapshot();
  modes.reset_modes();  // the start state in the modes a run starts in
  writer.sample(0.0, start.data(), no_work.data());
  modes.restore(final_modes);
  writer.sample(o.t_reached, o.y.data(), o.quadratures.data());
  columns = writer.columns();
  return writer.row();
}

double column(const std::vector<std::string>& columns, const std::vector<double>& row, const std::string& name) {
  const auto at = std::find(columns.begin(), columns.end(), name);
  INFO("energy.csv column " << name);
  REQUIRE(at != columns.end());
  return row[static_cast<std::size_t>(at - columns.begin())];
}

}  // namespace

TEST_CASE("a conservative model dissipates nothing and its energy error is named integration drift", "[dae][energy]") {
  // Two 40 t masses in a chain of elastic elements, no gravity, no damping: a linear spring
  // from ground to the first, a nonlinear spring (breakpoints in both directions) and a
  // torsional spring between the two; the first starts at 3 m/s and the second turning. The
  // exact motion keeps kinetic + elastic energy; whatever the integrator loses is its error,
  // attributed to no element. Explicit Euler with a coarse step (4 ms, about 1/70 of the shortest period)
  // makes that error large.
  const std::string text =
      "railcrash: 1\nname: chain\nunits: SI\ngravity: [0, 0]\nbodies:\n"
      "  - {name: first, mass: 40000, inertia: 40000, position: [10, 0], velocity: [3, 0]}\n"
      "  - {name: second, mass: 40000, inertia: 40000, position: [20, 0], angular_velocity: 0.5}\n"
      "elements:\n"
      "  - {name: anchor, type: linear_spring, stiffness: 4.0e6, points: [{body: ground, at: [0, 0]}, {body: first, at: [0, 0]}]}\n"
      "  - {name: gear, type: nonlinear_spring, compression_stiffness_1: 2.0e6, compression_stiffness_2: 8.0e6, "
      "compression_breakpoint: 0.05, extension_stiffness_1: 2.0e6, extension_stiffness_2: 6.0e6, extension_breakpoint: 0.08, "
      "points: [{body: first, at: [0, 0]}, {body: second, at: [0, 0]}]}\n"
      "  - {name: twist, type: torsional_spring, stiffness: 1.0e6, points: [{body: first, at: [0, 0]}, {body: second, at: [0, 0]}]}\n"
      "simulation: {t_end: 2, rtol: 1e-6, dt: 4.0e-3, integrator: ";
  for (const char* integrator : {"ida", "euler"}) {
    INFO(integrator);
    const LoadedModel loaded = testing::loaded_from_text(text + integrator + "}\n");
    const Model& model = loaded.model;
    DaeSystem system(model);
    const RunOutcome o = testing::simulate(system, loaded.run_spec.simulation);
    const EnergyBalance e = EnergyBalance::between(o.initial_energy, o.final_energy);
    const double initial = 0.5 * 40000.0 * 9.0 + 0.5 * 40000.0 * 0.25;
    REQUIRE(e.initial_total == Approx(initial).epsilon(1e-12));
    CHECK(e.dissipated == 0.0);
    const double final_total = e.kinetic + e.elastic;
    CHECK(e.integration_drift() == Approx(initial - final_total).margin(1e-12 * initial));
    // The coarse Euler step loses or gains a visible share: the check above is not vacuous.
    if (std::string(integrator) == "euler") CHECK(std::abs(e.integration_drift()) > 1e-4 * initial);
    std::vector<std::string> columns;
    const std::vector<double> row = energy_row(system, o, columns);
    for (const char* type : {"linear_spring", "nonlinear_spring", "torsional_spring"})
      CHECK(column(columns, row, std::string("dissipated.") + type) == 0.0);
    CHECK(column(columns, row, "dissipated") == 0.0);
    CHECK(column(columns, row, "integration_drift") == Approx(initial - final_total).margin(1e-12 * initial));
  }
}

TEST_CASE("a damped spring-mass dissipates the integral of c v^2 in its dashpot, and nothing in its spring",
          "[dae][energy]") {
  // m = 2 kg, k = 200 N/m, c = 4 N s/m (omega_0 = 10 rad/s, zeta = 0.1), released from rest
  // 0.1 m beyond the free length: v(t) = -x0 (omega_0^2 / omega_d) e^(-zeta omega_0 t) sin(omega_d t).
  const double m = 2.0, k = 200.0, c = 4.0, x0 = 0.1, t_end = 1.0;
  const double omega_0 = std::sqrt(k / m), zeta = c / (2.0 * std::sqrt(k * m));
  const double omega_d = omega_0 * std::sqrt(1.0 - zeta * zeta);
  const auto v = [&](double t) {
    return -x0 * omega_0 * omega_0 / omega_d * std::exp(-zeta * omega_0 * t) * std::sin(omega_d * t);
  };
  // The integral of c v^2 over [0, t_end] by Simpson's rule on 20000 panels (error ~1e-16 of it).
  const int panels = 20000;
  double sum = 0.0;
  for (int i = 0; i <= panels; ++i) {
    const double t = t_end * i / panels, weight = (i == 0 || i == panels) ? 1.0 : (i % 2 ? 4.0 : 2.0);
    sum += weight * c * v(t) * v(t);
  }
  const double damper_work = sum * t_end / panels / 3.0;
  REQUIRE(damper_work > 0.5 * 0.5 * k * x0 * x0);  // most of the initial 1 J is gone by t = 1
  const std::string text =
      "railcrash: 1\nname: damped\nunits: SI\ngravity: [0, 0]\nbodies:\n"
      "  - {name: bob, mass: 2, inertia: 0.1, position: [1.1, 0]}\n"
      "elements:\n"
      "  - {name: spring, type: linear_spring, stiffness: 200, free_length: 1, points: [{body: ground, at: [0, 0]}, {body: bob, at: [0, 0]}]}\n"
      "  - {name: damper, type: linear_dashpot, damping: 4, points: [{body: ground, at: [0, 0]}, {body: bob, at: [0, 0]}]}\n"
      "simulation: {t_end: 1, rtol: 1e-10, dt: 1.0e-5, integrator: ";
  for (const char* integrator : {"ida", "euler"}) {
    INFO(integrator);
    const LoadedModel loaded = testing::loaded_from_text(text + integrator + "}\n");
    const Model& model = loaded.model;
    const bool ida = std::string(integrator) == "ida";
    DaeSystem system(model);
    const RunOutcome o = testing::simulate(system, loaded.run_spec.simulation);
    const EnergyBalance e = EnergyBalance::between(o.initial_energy, o.final_energy);
    CHECK(e.dissipated == Approx(damper_work).epsilon(ida ? 1e-7 : 1e-4));
    std::vector<std::string> columns;
    const std::vector<double> row = energy_row(system, o, columns);
    CHECK(column(columns, row, "dissipated.linear_spring") == 0.0);
    CHECK(column(columns, row, "dissipated.linear_dashpot") == Approx(damper_work).epsilon(ida ? 1e-7 : 1e-4));
    CHECK(std::abs(column(columns, row, "integration_drift")) < (ida ? 1e-7 : 1e-4) * 0.5 * k * x0 * x0);
  }
}

TEST_CASE("an angle misfit counts as an opening at its bodies' size, wherever the model sits", "[dae][residual]") {
  // Two bodies on one point, joined rigidly (at the angle they start at), the second then
  // turned by 1 mrad about that point: the joint's angle
  // row misses by 1e-3 rad, its distance rows by nothing. The second body's radius of gyration,
  // sqrt(9 / 1) = 3 m, is the larger size: the misfit moves its points by up to 3 mm. Before,
  // the angle counted times the model's length scale, which grows with the distance from the
  // origin (10 km away it read 10 m).
  const auto model_at = [](double x) {
    char text[600];
    std::snprintf(text, sizeof text,
                  "railcrash: 1\nname: r\nunits: SI\ngravity: [0, 0]\nbodies:\n"
                  "  - {name: a, mass: 1.0, inertia: 1.0, position: [%.17g, 0]}\n"
                  "  - {name: b, mass: 1.0, inertia: 9.0, position: [%.17g, 0]}\n"
                  "elements:\n  - {name: weld, type: rigid_joint, points: [{body: a, at: [0, 0]}, {body: b, at: [0, 0]}]}\n"
                  "simulation: {t_end: 1}\n",
                  x, x);
    return testing::model_from_text(text);
  };
  for (const double x : {0.0, 1.0e4}) {
    INFO("model at x = " << x << " m");
    const Model model = model_at(x);
    const DaeSystem system(model);
    std::vector<double> y = system.initial_state();
    REQUIRE(system.constraint_residual(y.data()) == 0.0);
    y[5] += 1.0e-3;  // body b's angle [rad]
    CHECK(system.constraint_row_length(2) == Approx(3.0).epsilon(1e-15));
    CHECK(system.constraint_row_length(0) == 1.0);
    CHECK(system.constraint_residual(y.data()) == Approx(3.0e-3).epsilon(1e-9));
  }
}
