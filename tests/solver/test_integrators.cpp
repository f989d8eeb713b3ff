#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "railcrash/model/model_io.hpp"
#include "railcrash/results/responses.hpp"
#include "railcrash/results/results.hpp"
#include "railcrash/results/run.hpp"
#include "railcrash/solver/euler_integrator.hpp"
#include "railcrash/solver/stability_limit.hpp"
#include "railcrash/solver/ida_integrator.hpp"
#include "support.hpp"

using namespace railcrash;

namespace {

// Mass m on a spring k (and dashpot c) from the ground along x.
std::string oscillator(double k, double c, double t_end, const std::string& extra = "") {
  std::ostringstream s;
  s << "railcrash: 1\nname: osc\nunits: SI\ngravity: [0, 0]\nbodies:\n"
    << "  - {name: mass, mass: 2.0, inertia: 0.1, position: [1.1, 0]}\nelements:\n"
    << "  - {name: spring, type: linear_spring, stiffness: " << k << ", free_length: 1.0, "
    << "points: [{body: ground, at: [0, 0]}, {body: mass, at: [0, 0]}]}\n";
  if (c > 0.0)
    s << "  - {name: damper, type: linear_dashpot, damping: " << c
      << ", points: [{body: ground, at: [0, 0]}, {body: mass, at: [0, 0]}]}\n";
  s << "simulation: {t_end: " << t_end << extra << "}\n";
  return s.str();
}

struct CountingObserver : RunObserver {
  std::vector<double> times;
  void sample(double t, const double*, const double*, const double*, const double*) override { times.push_back(t); }
};

/// Checks the element outputs handed to sample() against the oscillator's sample state: spring
/// force and deformation, damper rate (the mass moves along x, away from the origin).
struct OscillatorOutputCheck : RunObserver {
  int samples = 0;
  void sample(double, const double* y, const double*, const double*, const double* outputs) override {
    ++samples;
    const double x = y[0], vx = y[3];             // [m], [m/s]
    CHECK(outputs[0] == Approx(200.0 * (x - 1.0)).margin(1e-12));  // spring.force [N]
    CHECK(outputs[1] == Approx(x - 1.0).margin(1e-14));            // spring.deformation [m]
    CHECK(outputs[3] == Approx(vx).margin(1e-14));                 // damper.rate [m/s]
  }
};

struct StopAfter : RunObserver {
  std::atomic<bool>* stop;
  int samples = 0;
  void sample(double, const double*, const double*, const double*, const double*) override {
    if (++samples == 3) stop->store(true);
  }
};

/// An observer that wants the forces at each sample: checks them and the outputs against the
/// system's own evaluation at the sample's state, bit for bit, and feeds two in-memory result
/// writers, one with the run loop's forces and one through sample(), which evaluates its own.
struct SampleForcesCheck : RunObserver {
  SampleForcesCheck(const DaeSystem& s, const RunSpec& run_spec) : system(s), with_forces("", s, run_spec), without_forces("", s, run_spec) {}
  const DaeSystem& system;
  ResultWriter with_forces, without_forces;
  int samples = 0, samples_with_forces = 0, mismatches = 0;
  bool wants_sample_forces() const override { return true; }
  void sample(double, const double*, const double*, const double*, const double*) override { ++samples; }
  void sample_with_forces(double t, const double* y, const double* lambda, const double* quadratures, const double* outputs,
                          const double* forces) override {
    ++samples_with_forces;
    const int nq = system.body_unknowns();
    std::vector<double> f(static_cast<std::size_t>(nq)), out(system.output_names().size());
    system.generalized_forces(t, y, y + nq, f.data(), nullptr, nullptr, lambda);
    system.outputs(y, lambda, out.data());
    if (!std::equal(f.begin(), f.end(), forces) || !std::equal(out.begin(), out.end(), outputs)) ++mismatches;
    with_forces.sample_with_forces(t, y, lambda, quadratures, outputs, forces);
    without_forces.sample(t, y, lambda, quadratures, outputs);
  }
};

}  // namespace

TEST_CASE("Euler stability limit matches 2 / (sqrt(w^2 + (c/2m)^2) + c/2m)", "[integrators]") {
  SECTION("undamped: 2 / omega") {
    const Model model = testing::model_from_text(oscillator(200.0, 0.0, 1.0));
    DaeSystem system(model);
    // omega = sqrt(200 / 2) = 10 along x; the other directions have no stiffness.
    CHECK(explicit_stability_limit(system, system.initial_state(), nullptr) == Approx(0.2).epsilon(1e-9));
  }
  SECTION("damped") {
    const Model model = testing::model_from_text(oscillator(200.0, 4.0, 1.0));
    DaeSystem system(model);
    const double half_rate = 4.0 / 2.0 / 2.0;  // c / (2 m)
    CHECK(explicit_stability_limit(system, system.initial_state(), nullptr) ==
          Approx(2.0 / (std::sqrt(100.0 + half_rate * half_rate) + half_rate)).epsilon(1e-9));
  }
}

TEST_CASE("Gershgorin bound for large models is safe and close for a long chain", "[integrators]") {
  // 250 masses in a chain of springs from the ground (750 unknowns: above the dense limit).
  std::ostringstream s;
  const int n = 250;
  s << "railcrash: 1\nname: chain\nunits: SI\ngravity: [0, 0]\nbodies:\n";
  for (int i = 0; i < n; ++i) s << "  - {name: m" << i << ", mass: 1.0, inertia: 1.0, position: [" << i + 1 << ", 0]}\n";
  s << "elements:\n";
  for (int i = 0; i < n; ++i)
    s << "  - {name: k" << i << ", type: linear_spring, stiffness: 100, points: [{body: " << (i == 0 ? "ground" : "m" + std::to_string(i - 1))
      << ", at: [" << (i == 0 ? "1" : "0") << ", 0]}, {body: m" << i << ", at: [0, 0]}]}\n";
  s << "simulation: {t_end: 1}\n";
  const Model model = testing::model_from_text(s.str());
  DaeSystem system(model);
  const double limit = explicit_stability_limit(system, system.initial_state(), nullptr);
  // Exact largest frequency of a fixed-free chain: 2 sqrt(k/m) sin((2n-1) pi / (2(2n+1))) < 2 sqrt(k/m).
  const double omega_max = 2.0 * 10.0 * std::sin((2.0 * n - 1.0) * M_PI / (2.0 * (2.0 * n + 1.0)));
  CHECK(limit <= 2.0 / omega_max);
  CHECK(limit >= 0.99 * 2.0 / omega_max);
}

TEST_CASE("Euler refuses a step above the stability limit unless forced, then reports divergence", "[integrators]") {
  LoadedModel loaded = testing::loaded_from_text(oscillator(200.0, 0.0, 200.0, ", integrator: euler, dt: 0.3"));
  Model& model = loaded.model;
  DaeSystem system(model);
  CHECK_THROWS_WITH(make_integrator(system, loaded.run_spec.simulation),
                    Catch::Contains("above the stability limit") && Catch::Contains("0.2"));
  loaded.run_spec.simulation.force_dt = true;
  auto integrator = make_integrator(system, loaded.run_spec.simulation);
  CountingObserver observer;
  const RunOutcome outcome = integrator->run(200.0, 1.0, observer);
  CHECK_FALSE(outcome.ok);
  CHECK_THAT(outcome.message, Catch::Contains("diverged"));
  CHECK(outcome.t_reached < 200.0);
}

TEST_CASE("Euler needs positive inertia", "[integrators]") {
  const LoadedModel loaded = testing::loaded_from_text(
      "railcrash: 1\nname: p\nunits: SI\nbodies:\n  - {name: dot, mass: 1, inertia: 0, position: [0, 0]}\n"
      "simulation: {t_end: 1, integrator: euler}\n");
  const Model& model = loaded.model;
  DaeSystem system(model);
  CHECK_THROWS_WITH(make_integrator(system, loaded.run_spec.simulation), Catch::Contains("'dot'") && Catch::Contains("zero inertia"));
}

TEST_CASE("Euler counts its steps to the t_end its settings give it, not the model file's", "[integrators]") {
  // The file says t_end 1; Euler takes t_end from its settings (CommonRunSettings): at dt 1e-3
  // it needs ceil(t_end / dt) steps, refused above max_steps.
  const Model model = testing::model_from_text(oscillator(200.0, 0.0, 1.0));
  DaeSystem system(model);
  EulerSettings settings;
  settings.dt = 1e-3;  // [s] below the stability limit 0.2 s
  settings.max_steps = 100;
  settings.run.t_end = 0.05;  // [s] 50 steps
  CHECK_NOTHROW(EulerIntegrator(system, settings));
  settings.run.t_end = 0.5;  // [s] 500 steps
  CHECK_THROWS_WITH(EulerIntegrator(system, settings),
                    Catch::Contains("needs 500 steps to reach t_end = 0.5, more than --max-steps 100"));
}

TEST_CASE("both integrators sample at t = 0, every output interval and t_end", "[integrators]") {
  for (const char* integrator : {"ida", "euler"}) {
    LoadedModel loaded = testing::loaded_from_text(oscillator(200.0, 1.0, 1.0, std::string(", integrator: ") + integrator + ", dt: 1e-3"));
    Model& model = loaded.model;
    DaeSystem system(model);
    auto run = make_integrator(system, loaded.run_spec.simulation);
    CountingObserver observer;
    const RunOutcome outcome = run->run(1.0, 0.25, observer);
    REQUIRE(outcome.ok);
    REQUIRE(observer.times.size() == 5);
    for (int k = 0; k < 5; ++k) CHECK(observer.times[static_cast<std::size_t>(k)] == Approx(0.25 * k).margin(1e-12));
    CHECK(outcome.t_reached == Approx(1.0));
  }
}

TEST_CASE("every sample hands the observer the element outputs of that sample's state", "[integrators]") {
  for (const char* integrator : {"ida", "euler"}) {
    LoadedModel loaded = testing::loaded_from_text(oscillator(200.0, 1.0, 1.0, std::string(", integrator: ") + integrator + ", dt: 1e-3"));
    Model& model = loaded.model;
    DaeSystem system(model);
    REQUIRE(system.output_names() == std::vector<std::string>{"spring.force", "spring.deformation", "damper.force", "damper.rate"});
    auto run = make_integrator(system, loaded.run_spec.simulation);
    OscillatorOutputCheck observer;
    REQUIRE(run->run(1.0, 0.05, observer).ok);
    CHECK(observer.samples == 21);
  }
}

TEST_CASE("an interrupted run stops early and says so", "[integrators]") {
  for (const char* integrator : {"ida", "euler"}) {
    LoadedModel loaded = testing::loaded_from_text(oscillator(200.0, 1.0, 1.0, std::string(", integrator: ") + integrator + ", dt: 1e-3"));
    Model& model = loaded.model;
    DaeSystem system(model);
    auto run = make_integrator(system, loaded.run_spec.simulation);
    std::atomic<bool> stop{false};
    StopAfter observer;
    observer.stop = &stop;
    const RunOutcome outcome = run->run(1.0, 0.1, observer, &stop);
    CHECK_FALSE(outcome.ok);
    CHECK_THAT(outcome.message, Catch::Contains("interrupted"));
    CHECK(outcome.t_reached == Approx(0.2).margin(1e-9));
  }
}

TEST_CASE("Euler refuses a dt that needs more than max_steps steps, before sizing penalties", "[integrators]") {
  // t_end 1 at dt 1e-300 needs 1e300 steps (a long step count would overflow); dt 1e-3 needs
  // exactly 1000 steps: refused at max_steps 999, accepted at 1000.
  LoadedModel loaded = testing::loaded_from_text(oscillator(200.0, 1.0, 1.0, ", integrator: euler, dt: 1e-300"));
  Model& model = loaded.model;
  DaeSystem tiny_step(model);
  CHECK_THROWS_WITH(make_integrator(tiny_step, loaded.run_spec.simulation),
                    Catch::Contains("needs 1e+300 steps to reach t_end = 1, more than --max-steps 10000000") &&
                        Catch::Contains("use a larger dt (above 1e-07)"));
  loaded.run_spec.simulation.dt = 1e-3;
  loaded.run_spec.simulation.max_steps = 999;
  DaeSystem system(model);
  CHECK_THROWS_WITH(make_integrator(system, loaded.run_spec.simulation), Catch::Contains("needs 1000 steps"));
  loaded.run_spec.simulation.max_steps = 1000;
  auto run = make_integrator(system, loaded.run_spec.simulation);
  CountingObserver observer;
  const RunOutcome outcome = run->run(1.0, 0.5, observer);
  CHECK(outcome.ok);
  CHECK(outcome.stats.steps == 1000);
  // Asked for a longer run than the model's t_end, the loop stops at max_steps: a failed run.
  const RunOutcome longer = run->run(2.0, 0.5, observer);
  CHECK_FALSE(longer.ok);
  CHECK_THAT(longer.message, Catch::Contains("after --max-steps 1000 steps of dt = 0.001, before t_end = 2"));
  CHECK(longer.t_reached == Approx(1.0).epsilon(1e-12));
}

TEST_CASE("IDA stops at max_steps as a failed run that says so", "[integrators]") {
  LoadedModel loaded = testing::loaded_from_text(oscillator(200.0, 1.0, 1.0));
  Model& model = loaded.model;
  loaded.run_spec.simulation.max_steps = 20;
  DaeSystem system(model);
  auto run = make_integrator(system, loaded.run_spec.simulation);
  CountingObserver observer;
  const RunOutcome outcome = run->run(1.0, 0.01, observer);
  CHECK_FALSE(outcome.ok);
  CHECK_THAT(outcome.message, Catch::Contains("after --max-steps 20 steps, before t_end = 1"));
  CHECK(outcome.t_reached < 1.0);
  CHECK(outcome.stats.steps <= 20);
}

TEST_CASE("a run whose element output is not finite fails naming the element", "[integrators]") {
  // The point at 1e308 is 2.7e308 from the circle's centre: the penetration overflows to -inf
  // while the contact stays open (no force, so the motion itself stays finite).
  const LoadedModel loaded = testing::loaded_from_text(
      "railcrash: 1\nname: far\nunits: SI\ngravity: [0, 0]\nbodies:\n"
      "  - {name: ball, mass: 2, inertia: 0.1, position: [1.0e308, 0], velocity: [1, 0]}\n"
      "  - {name: anchor, mass: 1, inertia: 0.1, position: [2, 0]}\nelements:\n"
      // an element with finite outputs before the contact: the bad column is not the first
      "  - {name: tether, type: linear_spring, stiffness: 10, free_length: 2, "
      "points: [{body: ground, at: [0, 0]}, {body: anchor, at: [0, 0]}]}\n"
      "  - {name: bump, type: contact, circle_center: [-1.7e308, 0], circle_radius: 1, stiffness: 1.0e6, "
      "points: [{body: ball, at: [0, 0]}]}\nsimulation: {t_end: 0.1, output_interval: 0.01}\n");
  const Model& model = loaded.model;
  const RunReport report = run_model(model, loaded.run_spec, "", nullptr, false);
  CHECK_FALSE(report.outcome.ok);
  CHECK_THAT(report.outcome.message, Catch::Contains("element 'bump' (contact): its output 'penetration' is -inf at t = 0"));
  // That sample and every later one is held back: nothing non-finite reaches the files.
  CHECK_THAT(report.outcome.message, Catch::Contains("the files hold no samples"));
  CHECK(report.outcome.t_reached == 0.0);
}

TEST_CASE("the dashpot's dissipated energy equals the energy the oscillator lost", "[integrators]") {
  const LoadedModel loaded = testing::loaded_from_text(oscillator(200.0, 4.0, 3.0, ", rtol: 1e-9"));
  const Model& model = loaded.model;
  DaeSystem system(model);
  auto run = make_integrator(system, loaded.run_spec.simulation);
  CountingObserver observer;
  const RunOutcome outcome = run->run(3.0, 0.1, observer);
  REQUIRE(outcome.ok);
  const EnergyBalance energy = EnergyBalance::between(outcome.initial_energy, outcome.final_energy);
  CHECK(energy.initial_total == Approx(0.5 * 200.0 * 0.01));
  // Work done on the dashpot (its own quadrature) against the mechanical energy lost.
  const double damper_work = outcome.quadratures[DaeSystem::kFirstElementWork + 1];
  CHECK(damper_work == Approx(energy.initial_total - energy.kinetic - energy.elastic).epsilon(1e-6));
  CHECK(damper_work > 0.9 * energy.initial_total);  // zeta = 0.1 over ~5 periods
}

TEST_CASE("run_model writes timeseries, events and summary, also for a failed run", "[integrators]") {
  const std::string dir = (testing::temp_path("railcrash_test_results")).string();
  std::filesystem::remove_all(dir);
  LoadedModel loaded = testing::loaded_from_text(oscillator(200.0, 0.0, 200.0, ", integrator: euler, dt: 0.3, force_dt: true, output_interval: 1"));
  Model& model = loaded.model;
  const RunReport report = run_model(model, loaded.run_spec, dir);
  CHECK_FALSE(report.outcome.ok);
  std::ifstream csv(dir + "/timeseries.csv");
  std::string header;
  std::getline(csv, header);  // the run's provenance (results/provenance.hpp)
  std::getline(csv, header);
  CHECK(header == "t,mass.x,mass.y,mass.theta,mass.vx,mass.vy,mass.omega,spring.force,spring.deformation");
  int rows = 0;
  for (std::string line; std::getline(csv, line);) ++rows;
  CHECK(rows >= 2);  // t = 0 and the samples before the divergence
  std::ifstream summary_file(dir + "/summary.json");
  std::stringstream summary;
  summary << summary_file.rdbuf();
  CHECK_THAT(summary.str(), Catch::Contains("\"status\": \"failed\"") && Catch::Contains("diverged") &&
                                Catch::Contains("\"integrator\": \"euler\""));
  std::ifstream events(dir + "/events.csv");
  std::getline(events, header);  // the run's provenance
  std::getline(events, header);
  CHECK(header == "t,element,event,value");
  std::filesystem::remove_all(dir);
}

TEST_CASE("Euler's divergence names the penalty joint with the largest violation", "[integrators][faults]") {
  // A 1 m pendulum on a pin joint with penalty stiffness 1e6 N/m: the row's effective mass
  // 1 / (1/1 + 1^2/0.01) = 1/101 kg gives w = 1e4 rad/s, stable below about 2e-4 s; forced to
  // run at 5e-3 s it diverges through the joint.
  LoadedModel loaded = testing::loaded_from_text(
      "railcrash: 1\nname: pendulum\nunits: SI\ngravity: [0, -9.81]\nbodies:\n"
      "  - {name: bob, mass: 1, inertia: 0.01, position: [1, 0]}\nelements:\n"
      "  - {name: hinge, type: pin_joint, penalty_stiffness: 1.0e6, "
      "points: [{body: ground, at: [0, 0]}, {body: bob, at: [-1, 0]}]}\n"
      "simulation: {t_end: 10, integrator: euler, dt: 5.0e-3, force_dt: true, output_interval: 0.01}\n");
  Model& model = loaded.model;
  DaeSystem system(model);
  auto integrator = make_integrator(system, loaded.run_spec.simulation);
  CountingObserver observer;
  const RunOutcome outcome = integrator->run(10.0, 0.01, observer);
  CHECK_FALSE(outcome.ok);
  CHECK_THAT(outcome.message, Catch::Contains("explicit Euler diverged") &&
                                  Catch::Contains("in test.yaml:8: joint 'hinge' (pin_joint), likely the penalty that went unstable"));
  CHECK(outcome.t_reached < 10.0);
}

TEST_CASE("IDA at rtol 1e-9 runs the barrier crash through and agrees with rtol 1e-8", "[integrators]") {
  // At 1e-9 the first step after a damper's restart (0.15 s) used to start so small that the
  // multipliers' Newton iteration never converged (IDA_CONV_FAIL, h = 1e-16); the restart is now
  // retried once with a first step of a tenth of the step before the event.
  const std::string path = std::string(RAILCRASH_SOURCE_DIR) + "/models/barrier/two_car_barrier.yaml";
  const LoadedModel tight_loaded = load_model(path, {"simulation.rtol=1e-9"});
  const Model& tight = tight_loaded.model;
  const LoadedModel loose_loaded = load_model(path, {"simulation.rtol=1e-8"});
  const RunOutcome a = testing::simulate(tight_loaded, 0.01), b = testing::simulate(loose_loaded, 0.01);
  REQUIRE(a.ok);
  const DaeSystem system(tight);
  double largest = 0.0;  // [in] largest difference of a body position at the end
  for (int k = 0; k < system.body_unknowns(); k += 3)
    largest = std::max({largest, std::abs(a.y[k] - b.y[k]), std::abs(a.y[k + 1] - b.y[k + 1])});
  INFO("largest position difference " << largest << " in");
  CHECK(largest < 1e-4);  // of bodies that moved about 80 in
  const double work_a = a.quadratures[DaeSystem::kFirstElementWork], work_b = b.quadratures[DaeSystem::kFirstElementWork];
  CHECK(std::abs(work_a - work_b) <= 1e-5 * std::abs(work_b));  // measured 2.5e-6 (the wall contact's work)
}

TEST_CASE("a timed run's phases add up to its wall time, each where its work is", "[integrators]") {
  // The barrier crash has every phase: IDA's Newton iterations, Jacobians, KLU, steps with
  // roots, located mode changes and restarts (the wall contact, the dampers).
  const std::string dir = (testing::temp_path("railcrash_test_phases")).string();
  std::filesystem::remove_all(dir);
  const LoadedModel loaded = load_model(std::string(RAILCRASH_SOURCE_DIR) + "/models/barrier/two_car_barrier.yaml",
                                 {"simulation.t_end=0.2"});
  const Model& model = loaded.model;
  const RunReport timed = run_model(model, loaded.run_spec, dir, nullptr, false, false, "csv", /*time_phases=*/true);
  REQUIRE(timed.outcome.ok);
  const RunStatistics& s = timed.outcome.stats;
  REQUIRE(s.phases_timed);
  const auto seconds = [&](Phase p) { return s.phase_seconds[static_cast<std::size_t>(p)]; };
  double sum = 0.0;
  for (const double x : s.phase_seconds) {
    CHECK(x >= 0.0);
    sum += x;
  }
  INFO("phases " << sum << " s, wall " << s.wall_seconds << " s");
  CHECK(std::abs(sum - s.wall_seconds) <= 1e-3 * s.wall_seconds + 1e-4);  // exclusive: nothing counted twice
  for (const Phase p : {Phase::Start, Phase::Residual, Phase::Jacobian, Phase::LinearSetup, Phase::LinearSolve,
                        Phase::StepSweep, Phase::Events, Phase::Output, Phase::Other})
    CHECK(seconds(p) > 0.0);
  REQUIRE(s.reinitializations > 0);
  CHECK(seconds(Phase::Restarts) > 0.0);
  CHECK(s.factor_nonzeros >= DaeSystem(model).pattern().nonzeros());  // L, U and the blocks off the diagonal hold at least A's entries
  std::ifstream summary_file(dir + "/summary.json");
  std::stringstream summary;
  summary << summary_file.rdbuf();
  CHECK_THAT(summary.str(), Catch::Contains("\"seconds\": {\"other\": ") && Catch::Contains("\"restarts\": ") &&
                                Catch::Contains("\"factor_nonzeros\": " + std::to_string(s.factor_nonzeros)));

  // Euler's phases: its force sweeps and mode changes; no Jacobian, no linear solver.
  const LoadedModel euler_loaded = load_model(std::string(RAILCRASH_SOURCE_DIR) + "/models/barrier/two_car_barrier.yaml",
                                 {"simulation.t_end=0.05", "simulation.integrator=euler"});
  const Model& euler = euler_loaded.model;
  const RunReport explicit_run = run_model(euler, euler_loaded.run_spec, "", nullptr, false, false, "csv", true);
  REQUIRE(explicit_run.outcome.stats.phases_timed);
  const auto& e = explicit_run.outcome.stats.phase_seconds;
  CHECK(e[static_cast<std::size_t>(Phase::Residual)] > 0.0);
  CHECK(e[static_cast<std::size_t>(Phase::Jacobian)] == 0.0);
  CHECK(e[static_cast<std::size_t>(Phase::LinearSolve)] == 0.0);
  CHECK(explicit_run.outcome.stats.factor_nonzeros == 0);

  // Untimed (the default): no phase figures, none in summary.json.
  const RunReport untimed = run_model(model, loaded.run_spec, dir);
  CHECK_FALSE(untimed.outcome.stats.phases_timed);
  for (const double x : untimed.outcome.stats.phase_seconds) CHECK(x == 0.0);
  CHECK_THAT(untimed.summary_json, !Catch::Contains("\"seconds\""));
  std::filesystem::remove_all(dir);
}

TEST_CASE("an observer that wants the forces gets them from the outputs' sweep, equal to generalized_forces", "[integrators]") {
  // A block sliding on a slider with friction (its force needs the multipliers) under both
  // integrators; the barrier crash's first 20 ms under IDA (contacts, crush springs, joints).
  const std::string slider =
      "railcrash: 1\nname: slide\nunits: SI\ngravity: [0, -9.81]\nbodies:\n"
      "  - {name: block, mass: 3.0, inertia: 0.2, position: [0, 0], velocity: [2, 0]}\n"
      "elements:\n  - {name: guide, type: slider_joint, axis: [1, 0], friction: 0.4, slider_length: 0.5, "
      "points: [{body: ground, at: [0, 0]}, {body: block, at: [0.1, 0]}]}\n"
      "  - {name: pull, type: linear_spring, stiffness: 50, free_length: 1.0, "
      "points: [{body: ground, at: [0, 0.5]}, {body: block, at: [0, 0]}]}\n"
      "simulation: {t_end: 0.3, dt: 1e-4}\n";
  const std::string barrier = std::string(RAILCRASH_SOURCE_DIR) + "/models/barrier/two_car_barrier.yaml";
  struct Case {
    LoadedModel loaded;
    IntegratorKind integrator;
    double t_end, interval;
  };
  std::vector<Case> cases;
  for (const IntegratorKind integrator : {IntegratorKind::Ida, IntegratorKind::Euler})
    cases.push_back({testing::loaded_from_text(slider), integrator, 0.3, 0.01});
  cases.push_back({load_model(barrier, {}), IntegratorKind::Ida, 0.02, 1e-3});
  for (Case& c : cases) {
    INFO(c.loaded.model.name << (c.integrator == IntegratorKind::Ida ? " under ida" : " under euler"));
    c.loaded.run_spec.simulation.integrator = c.integrator;
    DaeSystem system(c.loaded.model);
    auto run = make_integrator(system, c.loaded.run_spec.simulation);
    SampleForcesCheck observer(system, c.loaded.run_spec);
    REQUIRE(run->run(c.t_end, c.interval, observer).ok);
    CHECK(observer.samples == 0);  // every sample came with the forces
    CHECK(observer.samples_with_forces == static_cast<int>(std::lround(c.t_end / c.interval)) + 1);
    CHECK(observer.mismatches == 0);
    const auto& a = observer.with_forces.acceleration_peaks();
    const auto& b = observer.without_forces.acceleration_peaks();
    REQUIRE(a.size() == b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      CHECK(a[i].x == b[i].x);
      CHECK(a[i].y == b[i].y);
      CHECK(a[i].magnitude == b[i].magnitude);
      CHECK(a[i].t_magnitude == b[i].t_magnitude);
    }
    CHECK(std::any_of(a.begin(), a.end(), [](const AccelerationPeaks& p) { return p.magnitude > 0.0; }));
  }
}

namespace {

// A 2 kg mass between two springs from the ground along x, "tracked" (150 N/m) and "witness"
// (50 N/m), both at their free length of 1 m, the mass moving at v0 = 1 m/s: x(t) - 1 =
// (v0 / omega) sin(omega t) with omega = sqrt(200 / 2) = 10 rad/s; the tracked spring's force
// peaks at k v0 sqrt(m / (k + k_witness)) = 150 * 0.1 = 15 N at t = pi / 20 = 0.157 s.
std::string two_spring_oscillator(const std::string& simulation) {
  return "railcrash: 1\nname: two springs\nunits: SI\ngravity: [0, 0]\nbodies:\n"
         "  - {name: mass, mass: 2.0, inertia: 0.1, position: [1.0, 0], velocity: [1.0, 0]}\nelements:\n"
         "  - {name: tracked, type: linear_spring, stiffness: 150, free_length: 1.0, "
         "points: [{body: ground, at: [0, 0]}, {body: mass, at: [0, 0]}]}\n"
         "  - {name: witness, type: linear_spring, stiffness: 50, free_length: 1.0, "
         "points: [{body: ground, at: [0, 0]}, {body: mass, at: [0, 0]}]}\n"
         "simulation: {" + simulation + "}\n";
}

/// Reads one output column per step (tracked.force, column 0): the largest value over the
/// steps, the same force computed from each step's state alone, and the largest over the rows.
struct TrackedForcePeak : RunObserver {
  double step_peak = -1e300, state_peak = -1e300, row_peak = -1e300;  // [N]
  int steps = 0, rows = 0, witness_fresh = 0;
  void sample(double, const double*, const double*, const double*, const double* outputs) override {
    ++rows;
    row_peak = std::max(row_peak, outputs[0]);
  }
  void step(double, const double* y, const double*, const double* outputs, const FreshOutputs& fresh) override {
    ++steps;
    if (fresh.has(0)) step_peak = std::max(step_peak, outputs[0]);
    state_peak = std::max(state_peak, 150.0 * (std::abs(y[0]) - 1.0));  // the spring's length is |x| (y = 0)
    if (fresh.has(2) || fresh.has(3)) ++witness_fresh;
  }
  bool observes_steps() const override { return true; }
  void mark_step_columns(std::vector<char>& columns) const override { columns[0] = 1; }
};

/// Passes everything on to several observers (as the run's progress observer does).
struct FanOut : RunObserver {
  std::vector<RunObserver*> next;
  void sample(double t, const double* y, const double* lambda, const double* quadratures, const double* outputs) override {
    for (RunObserver* o : next) o->sample(t, y, lambda, quadratures, outputs);
  }
  void event(const EventRecord& record, const double* y) override {
    for (RunObserver* o : next) o->event(record, y);
  }
  void step(double t, const double* y, const double* lambda, const double* outputs, const FreshOutputs& fresh) override {
    for (RunObserver* o : next) o->step(t, y, lambda, outputs, fresh);
  }
  bool observes_steps() const override { return true; }
  void mark_step_columns(std::vector<char>& columns) const override {
    for (const RunObserver* o : next)
      if (o->observes_steps()) o->mark_step_columns(columns);
  }
};

/// Takes steps and reads every column (RunObserver::mark_step_columns' default), as the
/// result writer's peaks do.
struct ReadsEveryColumn : RunObserver {
  void sample(double, const double*, const double*, const double*, const double*) override {}
  void step(double, const double*, const double*, const double*, const FreshOutputs&) override {}
  bool observes_steps() const override { return true; }
};

}  // namespace

TEST_CASE("per step euler evaluates only the outputs an observer reads: an untracked element's at the output rows alone, the tracked peak still caught between rows",
          "[integrators][euler][output]") {
  LoadedModel loaded = testing::loaded_from_text(two_spring_oscillator("t_end: 0.3, integrator: euler, dt: 1.0e-4"));
  Model& model = loaded.model;
  DaeSystem system(model);
  REQUIRE(system.output_names() ==
          std::vector<std::string>{"tracked.force", "tracked.deformation", "witness.force", "witness.deformation"});
  auto run = make_integrator(system, loaded.run_spec.simulation);
  TrackedForcePeak observer;
  const RunOutcome outcome = run->run(0.3, 0.1, observer);  // rows at 0, 0.1, 0.2, 0.3 s; the peak at 0.157 s
  REQUIRE(outcome.ok);
  REQUIRE(outcome.stats.steps == 3000);
  REQUIRE(observer.rows == 4);
  // The witness spring's outputs: once per row (4), not at each of the 3,000 steps.
  CHECK(system.output_evaluations(1) == observer.rows);
  CHECK(observer.witness_fresh == 0);
  // The tracked spring's: at every step (and at the start and the rows).
  CHECK(system.output_evaluations(0) >= outcome.stats.steps);
  CHECK(observer.steps >= outcome.stats.steps);
  // Its peak is the per-step maximum of the force from the state, bit for bit the same
  // arithmetic up to the length's square root, near the analytic 15 N (Euler's 1e-3 step
  // angle), and well above the rows' largest (15 sin 2 = 13.6 N at 0.2 s).
  CHECK(observer.step_peak == Approx(observer.state_peak).epsilon(1e-12));
  CHECK(observer.step_peak == Approx(150.0 * 1.0 * std::sqrt(2.0 / 200.0)).epsilon(2e-3));
  CHECK(observer.row_peak < 13.7);
}

TEST_CASE("the responses from a run that evaluates only their outputs per step equal those of one that evaluates all, under euler",
          "[integrators][euler][output][responses]") {
  // The R1 model (a 1000 kg car end at 2 m/s into an anticlimber) with a soft spring beside the
  // anticlimber whose outputs no response reads.
  std::string text = testing::anticlimber_r1_model_text(0.1);
  const std::string spring =
      "  - {name: beside, type: linear_spring, stiffness: 1.0e3, free_length: 1.0, "
      "points: [{body: ground, at: [0, -1]}, {body: car, at: [0, 0]}]}\n";
  text.insert(text.find("responses:"), spring);
  const auto responses_json = [&](bool every_column) {
    LoadedModel loaded = testing::loaded_from_text(text);
    Model& model = loaded.model;
    SimulationSettings settings = loaded.run_spec.simulation;
    settings.integrator = IntegratorKind::Euler;
    settings.dt = 1e-5;
    DaeSystem system(model);
    REQUIRE(model.elements().size() == 2);
    auto run = make_integrator(system, settings);
    ResponseTracker responses(system, loaded.run_spec.responses);
    ReadsEveryColumn every;
    FanOut observers;
    observers.next = {&responses};
    if (every_column) observers.next.push_back(&every);
    REQUIRE(run->run(0.1, 0.02, observers).ok);  // rows at 0, 0.02, ..., 0.1 s
    std::vector<long> evaluations;
    for (std::size_t e = 0; e < model.elements().size(); ++e) evaluations.push_back(system.output_evaluations(static_cast<int>(e)));
    return std::make_pair(responses.json(), evaluations);
  };
  const auto [some, some_evaluations] = responses_json(false);
  const auto [all, all_evaluations] = responses_json(true);
  CHECK(some == all);
  CHECK(some.find("\"max_anticlimber_crush\": 0,") == std::string::npos);  // (the anticlimber was loaded)
  // The spring beside it: at the 6 rows alone when only the responses read outputs per step,
  // at every one of the 10,000 steps when an observer reads every column.
  CHECK(some_evaluations[1] == 6);
  CHECK(all_evaluations[1] > 10000);
  CHECK(some_evaluations[0] == all_evaluations[0]);  // the anticlimber's: every step either way
}

TEST_CASE("an SI two-car crash under euler gives the same responses without a result writer, which reads only the anticlimber per step, as with one, which reads every output",
          "[integrators][euler][output][responses]") {
  // Two 40 t multiple-unit cars (a 38 t body and a 2 t end each), 8 m/s into a standing one:
  // each end on a crush zone (1.2 MN plateau over 0.5 m) beside a draft gear, sliding on its
  // body; the ends meet through an anticlimber (2 MN yield); no gravity.
  const std::string text =
      "railcrash: 1\nname: two 40 t cars, 8 m/s\nunits: SI\ngravity: [0, 0]\nbodies:\n"
      "  - {name: a_body, car: a, mass: 38000, inertia: 1.2e6, position: [0.0, 1.4], velocity: [8.0, 0]}\n"
      "  - {name: a_end, car: a, mass: 2000, inertia: 400, position: [10.4, 1.4], velocity: [8.0, 0]}\n"
      "  - {name: b_end, car: b, mass: 2000, inertia: 400, position: [10.43, 1.4]}\n"
      "  - {name: b_body, car: b, mass: 38000, inertia: 1.2e6, position: [20.8305, 1.4]}\n"
      "elements:\n"
      "  - {name: a_crush_zone, type: crush_spring, free_length: 0.4, curve: [[0, 0], [0.03, 1.2e6], [0.5, 1.2e6], [0.55, 2.5e6]],\n"
      "     unloading_stiffness: 5.0e7, points: [{body: a_body, at: [10.0, 0]}, {body: a_end, at: [0, 0]}]}\n"
      "  - {name: a_draft_gear, type: draft_gear, initial_stiffness: 4.0e6, travel: 0.07, stiffness_after_bottoming: 1.0e5,\n"
      "     hysteresis_load: 8.0e4, transition_stiffness: 1.0e8, points: [{body: a_body, at: [10.0, -0.4]}, {body: a_end, at: [0, -0.4]}]}\n"
      "  - {name: b_crush_zone, type: crush_spring, free_length: 0.4, curve: [[0, 0], [0.03, 1.2e6], [0.5, 1.2e6], [0.55, 2.5e6]],\n"
      "     unloading_stiffness: 5.0e7, points: [{body: b_end, at: [0, 0]}, {body: b_body, at: [-10.0, 0]}]}\n"
      "  - {name: b_draft_gear, type: draft_gear, initial_stiffness: 4.0e6, travel: 0.07, stiffness_after_bottoming: 1.0e5,\n"
      "     hysteresis_load: 8.0e4, transition_stiffness: 1.0e8, points: [{body: b_end, at: [0, -0.4]}, {body: b_body, at: [-10.0, -0.4]}]}\n"
      "  - {name: a_guide, type: slider_joint, axis: [1, 0], points: [{body: a_body, at: [10.0, 0]}, {body: a_end, at: [0, 0]}]}\n"
      "  - {name: b_guide, type: slider_joint, axis: [1, 0], points: [{body: b_body, at: [-10.0, 0]}, {body: b_end, at: [0, 0]}]}\n"
      "  - {name: anticlimber, type: anticlimber, points: [{body: a_end, at: [0, 0]}, {body: b_end, at: [0, 0]}],\n"
      "     horizontal_elastic_stiffness: 8.0e8, horizontal_plastic_stiffness: 1.0e6, horizontal_yield_deflection: 0.0025,\n"
      "     vertical_elastic_stiffness: 5.0e7, vertical_plastic_stiffness: 1.0e5, vertical_yield_deflection: 0.005,\n"
      "     torsional_elastic_stiffness: 1.0e7, torsional_plastic_stiffness: 1.0e5, torsional_yield_deflection: 0.01,\n"
      "     face_height: 0.3, length: 0.2}\n"
      "responses: {crush: anticlimber, reference_crush: 0.01, anticlimber: anticlimber, reference_velocity: 8.0}\n"
      "simulation: {t_end: 0.05, integrator: euler, dt: 2.0e-6, output_interval: 0.005}\n";
  const LoadedModel loaded = testing::loaded_from_text(text);
  const Model& model = loaded.model;
  const RunReport alone = run_model(model, loaded.run_spec, "", nullptr);  // the responses alone (sensitivity's runs)
  const RunReport with_writer = run_model(model, loaded.run_spec, "", nullptr, false, /*keep_in_memory=*/true);  // every column (the API's)
  REQUIRE(alone.outcome.ok);
  REQUIRE(with_writer.outcome.ok);
  REQUIRE(alone.has_responses);
  CHECK(alone.outcome.stats.steps == with_writer.outcome.stats.steps);
  CHECK(alone.outcome.stats.steps > 1000);
  CHECK(alone.responses.max_anticlimber_crush > 0.0025);  // past its yield
  CHECK(alone.responses.max_anticlimber_crush == with_writer.responses.max_anticlimber_crush);
  CHECK(alone.responses.max_vertical_force == with_writer.responses.max_vertical_force);
  CHECK(alone.responses.r1 == with_writer.responses.r1);
  CHECK(alone.responses.r2 == with_writer.responses.r2);
  CHECK(alone.responses.r3 == with_writer.responses.r3);
  CHECK(alone.outcome.y == with_writer.outcome.y);
}
