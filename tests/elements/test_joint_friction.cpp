#include <catch2/catch.hpp>

#include <cmath>
#include <sstream>

#include "railcrash/results/run.hpp"
#include "support.hpp"

using namespace railcrash;

namespace {

const double kG = 9.81;

RunOutcome run(const LoadedModel& loaded) { return testing::simulate(loaded); }

// A 3 kg block on a horizontal ground slider (friction mu, slider length 0.5 m), pushed
// off at v0; P2 is its centre of mass, so the lock carries no moment and N = m g.
std::string slider(double mu, double v0, const std::string& integrator) {
  std::ostringstream s;
  s << "railcrash: 1\nname: slide\nunits: SI\ngravity: [0, " << -kG << "]\nbodies:\n"
    << "  - {name: block, mass: 3.0, inertia: 0.2, position: [0, 0], velocity: [" << v0 << ", 0]}\n"
    << "elements:\n  - {name: guide, type: slider_joint, axis: [1, 0], friction: " << mu
    << ", slider_length: 0.5, friction_velocity: 1.0e-4, points: [{body: ground, at: [0, 0]}, {body: block, at: [0, 0]}]}\n"
    << "simulation: {t_end: 1.0, rtol: 1e-9, dt: 1e-5, integrator: " << integrator << "}\n";
  return s.str();
}

// A disc (J = 0.5) pinned at its centre, spinning at w0 under gravity: the pin carries m g.
std::string wheel(double friction_radius, double w0, const std::string& integrator) {
  std::ostringstream s;
  s << "railcrash: 1\nname: spin\nunits: SI\ngravity: [0, " << -kG << "]\nbodies:\n"
    << "  - {name: disc, mass: 4.0, inertia: 0.5, position: [0, 0], angular_velocity: " << w0 << "}\n"
    << "elements:\n  - {name: axle, type: pin_joint, friction_radius: " << friction_radius
    << ", friction_velocity: 1.0e-4, points: [{body: ground, at: [0, 0]}, {body: disc, at: [0, 0]}]}\n"
    << "simulation: {t_end: 4.0, rtol: 1e-9, dt: 1e-5, integrator: " << integrator << "}\n";
  return s.str();
}

}  // namespace

TEST_CASE("slider friction stops a block at v0^2 / (2 mu g) under both integrators", "[elements][friction]") {
  const double mu = 0.4, v0 = 2.0;
  for (const char* integrator : {"ida", "euler"}) {
    INFO(integrator);
    const RunOutcome o = run(testing::loaded_from_text(slider(mu, v0, integrator)));
    CHECK(o.y[0] == Approx(v0 * v0 / (2.0 * mu * kG)).epsilon(2e-3));
    CHECK(std::abs(o.y[3]) < 1e-3);
    // Everything it had is dissipated by the joint's friction.
    const EnergyBalance e = EnergyBalance::between(o.initial_energy, o.final_energy);
    CHECK(o.quadratures[DaeSystem::kFirstElementWork] == Approx(0.5 * 3.0 * v0 * v0).epsilon(2e-3));
    CHECK(e.dissipated == Approx(0.5 * 3.0 * v0 * v0).epsilon(2e-3));
  }
}

TEST_CASE("pin friction decelerates a spinning disc at muR m g / J", "[elements][friction]") {
  const double friction_radius = 0.02, w0 = 5.0, m = 4.0, j = 0.5;
  const double stop_time = w0 * j / (friction_radius * m * kG);  // 3.19 s
  for (const char* integrator : {"ida", "euler"}) {
    INFO(integrator);
    const RunOutcome o = run(testing::loaded_from_text(wheel(friction_radius, w0, integrator)));
    // Constant deceleration until it stops: angle w0^2 / (2 alpha), then at rest.
    const double alpha = w0 / stop_time;
    CHECK(o.y[2] == Approx(w0 * w0 / (2.0 * alpha)).epsilon(2e-3));
    CHECK(std::abs(o.y[5]) < 1e-3);
  }
}

TEST_CASE("joint friction Jacobians match central differences, multipliers included", "[elements][friction]") {
  // Body-to-body joints with offset points, a tilted axis and turning bodies, so every term
  // of the friction laws (arms, axis rotation, slip of body 1 under P2) is exercised.
  const std::string bodies =
      "railcrash: 1\nname: j\nunits: SI\ngravity: [0, -9.81]\nbodies:\n"
      "  - {name: a, mass: 3.0, inertia: 0.2, position: [0, 0], angle: 0.3, angular_velocity: 0.7}\n"
      "  - {name: b, mass: 2.0, inertia: 0.1, position: [0.5, 0.4], angle: -0.2, velocity: [0.3, -0.1]}\nelements:\n";
  for (const std::string& joint :
       {std::string("  - {name: j, type: slider_joint, axis: [0.6, 0.8], friction: 0.4, slider_length: 0.5, "
                    "friction_velocity: 0.05, points: [{body: a, at: [0.2, 0.1]}, {body: b, at: [-0.1, 0.3]}]}\n"),
        std::string("  - {name: j, type: pin_joint, friction_radius: 0.03, friction_velocity: 0.05, "
                    "points: [{body: a, at: [0.2, 0.1]}, {body: b, at: [-0.1, 0.3]}]}\n")}) {
    const Model model = testing::model_from_text(bodies + joint + "simulation: {t_end: 1}\n");
    DaeSystem system(model);
    std::mt19937 rng(5);
    for (int trial = 0; trial < 5; ++trial) {
      const std::vector<double> y = testing::random_state(system, rng, 0.5);
      const std::vector<double> yp = testing::random_state(system, rng, 0.5);
      double outside = 0.0;
      CHECK(testing::jacobian_error(system, 0.0, 20.0, y, yp, &outside) < 1e-6);
      CHECK(outside == 0.0);
    }
  }
}

TEST_CASE("a slider with friction needs its length", "[elements][friction]") {
  std::string text = slider(0.4, 2.0, "ida");
  text.erase(text.find("slider_length: 0.5, "), std::string("slider_length: 0.5, ").size());
  CHECK_THROWS_WITH(testing::model_from_text(text), Catch::Contains("test.yaml:") && Catch::Contains("slider_length"));
}
