#include <catch2/catch.hpp>

#include <cmath>
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
