// The Jacobian kept between IDA's setups (IdaSettings::jacobian_kept_steps,
// DaeSystem::add_rate_jacobian; bench/HISTORY.md, "The Jacobian kept between setups").
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "railcrash/model/model_io.hpp"
#include "railcrash/results/run.hpp"
#include "railcrash/solver/ida_integrator.hpp"
#include "support.hpp"

using namespace railcrash;

namespace {

/// A run of the loaded model under IDA, as `run` makes it (make_integrator), with its Jacobian
/// kept for kept_steps steps (simulation: jacobian_kept_steps).
RunOutcome run_ida(const LoadedModel& loaded, long kept_steps) {
  SimulationSettings simulation = loaded.run_spec.simulation;
  simulation.integrator = IntegratorKind::Ida;
  simulation.jacobian_kept_steps = kept_steps;
  DaeSystem system(loaded.model);
  return testing::simulate(system, simulation, output_interval_of(simulation));  // (REQUIREs ok)
}

}  // namespace

TEST_CASE("the rates' part of the Jacobian turns one cj's matrix into another's", "[dae][jacobian]") {
  for (const char* file : {"/models/examples/mu_3plus3_si.yaml", "/verification/cases/slider_crank.yaml"}) {
    INFO(file);
    const Model model = load_model(std::string(RAILCRASH_SOURCE_DIR) + file).model;
    DaeSystem system(model);
    std::mt19937 rng(11);
    const std::size_t entries = static_cast<std::size_t>(system.pattern().nonzeros());
    for (int trial = 0; trial < 3; ++trial) {
      const std::vector<double> y = testing::random_state(system, rng);
      const std::vector<double> yp = testing::random_state(system, rng);
      const double cj_old = 1e3 * (trial + 1), cj_new = 7.3e4 / (trial + 1);  // [1/s]
      std::vector<double> kept(entries), fresh(entries);
      system.jacobian(0.1, cj_old, y.data(), yp.data(), kept.data());
      system.add_rate_jacobian(cj_new - cj_old, kept.data());
      system.jacobian(0.1, cj_new, y.data(), yp.data(), fresh.data());
      double largest = 0.0, difference = 0.0;
      for (std::size_t k = 0; k < entries; ++k) {
        largest = std::max(largest, std::abs(fresh[k]));
        difference = std::max(difference, std::abs(kept[k] - fresh[k]));
      }
      CHECK(largest > 0.0);
      CHECK(difference <= 1e-13 * largest);
    }
  }
}

TEST_CASE("IDA keeps the elements' Jacobian between setups and ends where a Jacobian at every setup ends",
          "[solver][ida][jacobian]") {
  // Models with crush zones, anticlimbers, draft gears and bogies: the SI 3+3-car multiple
  // unit to 0.2 s (its leading end structures crushing) and the report's two-car crash to 0.1 s.
  struct Case {
    const char* file;
    const char* t_end;
  };
  for (const Case c : {Case{"/models/examples/mu_3plus3_si.yaml", "0.2"}, Case{"/models/report/final_two_car.yaml", "0.1"}}) {
    INFO(c.file);
    const LoadedModel loaded =
        load_model(std::string(RAILCRASH_SOURCE_DIR) + c.file, {"simulation.integrator=ida", std::string("simulation.t_end=") + c.t_end});
    const RunOutcome every = run_ida(loaded, 0);
    const RunOutcome kept = run_ida(loaded, IdaSettings{}.jacobian_kept_steps);
    // Every setup evaluated its Jacobian, or half or fewer of them did (measured: a third).
    CHECK(every.stats.jacobian_evaluations == every.stats.linear_setups);
    CHECK(kept.stats.jacobian_evaluations * 2 < kept.stats.linear_setups);
    // As accurate: modified Newton iterates to the same solution with either matrix, so both
    // runs lie within IDA's tolerance of an independent run at rtol 1e-8 (every body's x and y).
    const LoadedModel tight_loaded = load_model(std::string(RAILCRASH_SOURCE_DIR) + c.file,
                                                {"simulation.integrator=ida", std::string("simulation.t_end=") + c.t_end,
                                                 "simulation.rtol=1e-8"});
    const RunOutcome tight = run_ida(tight_loaded, 0);
    const int nq = DaeSystem(loaded.model).body_unknowns();
    double error_every = 0.0, error_kept = 0.0;  // [length]
    for (int k = 0; k < nq; k += 3)
      for (int i = k; i < k + 2; ++i) {
        error_every = std::max(error_every, std::abs(every.y[i] - tight.y[i]));
        error_kept = std::max(error_kept, std::abs(kept.y[i] - tight.y[i]));
      }
    INFO("position error against rtol 1e-8: a Jacobian at every setup " << error_every << ", kept " << error_kept);
    CHECK(error_kept < 2.0 * error_every);
    CHECK(kept.stats.steps < 1.1 * static_cast<double>(every.stats.steps));
  }
}

TEST_CASE("a Jacobian is evaluated afresh after an element changes mode, and Newton fails no more often for the kept ones",
          "[solver][ida][jacobian]") {
  // The 3-car SI unit into a wall: 8,300 steps, 280 restarts and as many mode changes crossed
  // without one (crush zones unloading and reloading, bump stops, couplers). A crush zone
  // reloading or an anticlimber touching changes the elements' Jacobian by up to 1e9 N/m, which
  // a kept matrix would not know: its Newton iteration could fail and IDA would cut its step.
  // Measured: 2 Newton failures with a Jacobian at every setup, 2 kept; 5 kept across mode
  // changes as well (the modes' check taken out).
  const LoadedModel loaded =
      load_model(std::string(RAILCRASH_SOURCE_DIR) + "/models/examples/emu3_wall.yaml", {"simulation.integrator=ida"});
  const RunOutcome every = run_ida(loaded, 0);
  const RunOutcome kept = run_ida(loaded, IdaSettings{}.jacobian_kept_steps);
  CHECK(kept.stats.nonlinear_convergence_failures <= every.stats.nonlinear_convergence_failures);
  CHECK(kept.stats.jacobian_evaluations * 3 < kept.stats.linear_setups);  // measured 447 of 1,702
}

TEST_CASE("jacobian_kept_steps: the model file's key takes a whole number of at least 0, and names the line of anything else",
          "[solver][ida][model]") {
  const auto model = [](const std::string& steps) {
    return "railcrash: 1\nname: oscillator\nunits: SI\ngravity: [0, 0]\nbodies:\n"
           "  - {name: bob, mass: 1.0, inertia: 0.1, position: [1.0, 0]}\nelements:\n"
           "  - {name: spring, type: linear_spring, stiffness: 100.0, free_length: 1.0, points: [{body: ground, at: [0, 0]}, "
           "{body: bob, at: [0, 0]}]}\n"
           "simulation: {t_end: 0.5, integrator: ida" +
           (steps.empty() ? std::string() : ", jacobian_kept_steps: " + steps) + "}\n";
  };
  CHECK(testing::loaded_from_text(model("")).run_spec.simulation.jacobian_kept_steps == IdaSettings{}.jacobian_kept_steps);
  CHECK(testing::loaded_from_text(model("0")).run_spec.simulation.jacobian_kept_steps == 0);
  CHECK(testing::loaded_from_text(model("50")).run_spec.simulation.jacobian_kept_steps == 50);
  for (const char* bad : {"-1", "2.5", "many"}) {
    INFO(bad);
    try {
      testing::loaded_from_text(model(bad));
      FAIL("a jacobian_kept_steps of " << bad << " was taken");
    } catch (const InputError& e) {
      CHECK_THAT(e.what(), Catch::Contains("test.yaml:9"));
      CHECK_THAT(e.what(), Catch::Contains("jacobian_kept_steps"));
    }
  }
  // The report's models evaluate at every setup, as when their documented runs and studies
  // were made (README "Jacobians kept"); the SI units keep the default.
  for (const char* file : {"/models/report/final_two_car.yaml", "/models/report/preliminary_car.yaml",
                           "/models/report/final_two_car_corrected.yaml", "/models/report/preliminary_car_printed.yaml",
                           "/models/scenarios/scenario1_report_car.yaml", "/models/scenarios/scenario2_report_car.yaml"}) {
    INFO(file);
    CHECK(load_model(std::string(RAILCRASH_SOURCE_DIR) + file).run_spec.simulation.jacobian_kept_steps == 0);
  }
  CHECK(load_model(std::string(RAILCRASH_SOURCE_DIR) + "/models/examples/mu_3plus3_si.yaml").run_spec.simulation.jacobian_kept_steps ==
        IdaSettings{}.jacobian_kept_steps);
}

TEST_CASE("with a Jacobian at every setup IDA passes the N-four-bar's singular configurations (README: jacobian_kept_steps 0)",
          "[solver][ida][jacobian]") {
  // Forty parallelogram four-bars in series pass through two singular configurations (0.72 and
  // 1.24 s), where the joints' equations lose rank. Evaluated at every setup, IDA passes both at
  // rtol 1e-8; with the Jacobian kept (the default) it fails at one of them from rtol 1e-5 on
  // (README "Jacobians kept"), naming the configuration.
  const LoadedModel loaded = load_model(std::string(RAILCRASH_SOURCE_DIR) + "/tests/robustness/models/n_four_bar.yaml",
                                        {"simulation.integrator=ida", "simulation.rtol=1e-8"});
  const RunOutcome every = run_ida(loaded, 0);  // (REQUIREs ok)
  CHECK(every.t_reached == Approx(loaded.run_spec.simulation.t_end));
}
