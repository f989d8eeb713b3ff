#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "railcrash/model_io.hpp"
#include "support.hpp"

using namespace railcrash;

TEST_CASE("slider-crank Jacobian matches central differences at random states", "[dae]") {
  const Model model = load_model(std::string(RAILCRASH_SOURCE_DIR) + "/verification/cases/slider_crank.yaml");
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
  const Model model = load_model(std::string(RAILCRASH_SOURCE_DIR) + "/models/report/final_two_car.yaml");
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
  const Model model = load_model(std::string(RAILCRASH_SOURCE_DIR) + "/models/report/final_two_car.yaml");
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
