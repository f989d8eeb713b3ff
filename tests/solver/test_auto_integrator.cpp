#include <catch2/catch.hpp>

#include <cmath>
#include <sstream>

#include "railcrash/model/model_io.hpp"
#include "railcrash/results/run.hpp"
#include "railcrash/solver/auto_integrator.hpp"
#include "support.hpp"

using namespace railcrash;

namespace {

std::string source_path(const std::string& relative) { return std::string(RAILCRASH_SOURCE_DIR) + "/" + relative; }

// A 2 kg mass on a 200 N/m spring from the ground along x, released 0.1 m from rest:
// x(t) - 1 = 0.1 cos(10 t).
std::string oscillator(double t_end, const std::string& extra = "") {
  std::ostringstream s;
  s << "railcrash: 1\nname: osc\nunits: SI\ngravity: [0, 0]\nbodies:\n"
    << "  - {name: mass, mass: 2.0, inertia: 0.1, position: [1.1, 0]}\nelements:\n"
    << "  - {name: spring, type: linear_spring, stiffness: 200, free_length: 1.0, "
    << "points: [{body: ground, at: [0, 0]}, {body: mass, at: [0, 0]}]}\n"
    << "simulation: {t_end: " << t_end << extra << "}\n";
  return s.str();
}

struct SampleTimes : RunObserver {
  std::vector<double> times;
  void sample(double t, const double*, const double*, const double*, const double*) override { times.push_back(t); }
};

IdaSettings ida_settings(const SimulationSettings& s) {
  IdaSettings ida;
  ida.rtol = s.rtol;
  ida.atol = s.atol;
  ida.run = {s.t_end, s.static_equilibrium};
  return ida;
}

EulerSettings euler_settings(const SimulationSettings& s) {
  return {s.dt, s.force_dt, s.penalty, s.max_steps, {s.t_end, s.static_equilibrium}};
}

/// auto's rule set to hand the run to Euler at the first chance: after IDA's sixth step, with
/// no events, span or margin asked for and the resolution check off.
AutoSettings hand_over_at_first_chance() {
  AutoSettings rule;
  rule.startup_steps = 5;
  rule.min_events = 0;
  rule.min_span_steps = 0.0;
  rule.margin = 0.0;
  rule.require_resolution = false;
  return rule;
}

}  // namespace

TEST_CASE("IDA hands a run to Euler that goes on from its state with the run's samples and counters", "[integrators][auto]") {
  const double dt = 1e-4, t_end = 2.0, interval = 0.01;  // [s]
  const LoadedModel loaded = testing::loaded_from_text(oscillator(t_end, ", dt: 1e-4"));
  DaeSystem system(loaded.model);
  const AutoSettings rule = hand_over_at_first_chance();
  AutoIntegrator integrator(system, ida_settings(loaded.run_spec.simulation), euler_settings(loaded.run_spec.simulation), rule);
  SampleTimes observer;
  const RunOutcome outcome = integrator.run(t_end, interval, observer);
  REQUIRE(outcome.ok);
  const double t_switch = outcome.stats.handed_over_at;
  INFO(outcome.stats.hand_over_reason);
  REQUIRE(t_switch > 0.0);
  CHECK(t_switch < 0.1);
  CHECK_THAT(outcome.stats.hand_over_reason, Catch::Contains("handed the run to Euler at t = "));
  // Euler's steps run from the hand-over on its own grid t_switch + k dt, the last one ending at t_end.
  const auto euler_steps = static_cast<long>(std::ceil((t_end - t_switch) / dt - 1e-9));
  CHECK(outcome.stats.steps == rule.startup_steps + 1 + euler_steps);
  CHECK(outcome.stats.last_step == dt);
  // A sample per output time: IDA's on the times, Euler's at the end of the step that passes one.
  REQUIRE(observer.times.size() == 201);
  for (std::size_t k = 0; k < observer.times.size(); ++k) {
    const double t_out = std::min(t_end, static_cast<double>(k) * interval);
    CHECK(observer.times[k] >= t_out * (1.0 - 1e-12));
    CHECK(observer.times[k] <= t_out + dt * (1.0 + 1e-9));
  }
  // The motion goes on: the analytic solution within Euler's error (omega dt = 1e-3).
  CHECK(outcome.y[0] - 1.0 == Approx(0.1 * std::cos(10.0 * t_end)).margin(3e-4));
  // Energy books carried across: the spring's initial 1 J, held by semi-implicit Euler to O(omega dt).
  CHECK(outcome.initial_energy.elastic == Approx(1.0).epsilon(1e-12));
  CHECK(outcome.final_energy.kinetic + outcome.final_energy.elastic == Approx(1.0).epsilon(3e-3));
}

TEST_CASE("auto keeps IDA on the report's two-car crash and gives IDA's result bit for bit", "[integrators][auto]") {
  const std::string file = source_path("models/report/final_two_car.yaml");
  const LoadedModel ida_loaded = load_model(file, {"simulation.t_end=0.02", "simulation.integrator=ida"});
  const Model& ida_model = ida_loaded.model;
  const LoadedModel auto_loaded = load_model(file, {"simulation.t_end=0.02", "simulation.integrator=auto"});
  const Model& auto_model = auto_loaded.model;
  DaeSystem ida_system(ida_model), auto_system(auto_model);
  SampleTimes a, b;
  const RunOutcome by_ida = make_integrator(ida_system, ida_loaded.run_spec.simulation)->run(0.02, 0.001, a);
  const RunOutcome by_auto = make_integrator(auto_system, auto_loaded.run_spec.simulation)->run(0.02, 0.001, b);
  REQUIRE(by_ida.ok);
  REQUIRE(by_auto.ok);
  INFO(by_auto.stats.hand_over_reason);
  CHECK(by_auto.stats.handed_over_at < 0.0);
  CHECK_THAT(by_auto.stats.hand_over_reason, Catch::StartsWith("IDA kept the run") && Catch::Contains("cheaper"));
  CHECK(by_auto.y == by_ida.y);
  CHECK(by_auto.stats.steps == by_ida.stats.steps);
  CHECK(by_auto.events.size() == by_ida.events.size());
}

TEST_CASE("auto keeps IDA on an SI multiple-unit crash whose IDA steps are shorter than Euler's", "[integrators][auto]") {
  // bench/HISTORY.md "integrator: auto": Euler at its own step is cheaper here but 3-11 % off in
  // the energy the crush zones absorb; IDA's mean step is a sixth of Euler's.
  const LoadedModel loaded = load_model(source_path("models/examples/emu_two_car_crush_zones.yaml"),
                                 {"simulation.integrator=auto", "simulation.output_interval=0.01"});
  const RunOutcome outcome = testing::simulate(loaded, 0.01);
  INFO(outcome.stats.hand_over_reason);
  CHECK(outcome.stats.handed_over_at < 0.0);
  CHECK_THAT(outcome.stats.hand_over_reason, Catch::Contains("shorter than Euler's"));
}

TEST_CASE("auto keeps IDA where Euler cannot run the model and says why", "[integrators][auto]") {
  // dt 1 s is above the oscillator's stability limit 2 / omega = 0.2 s.
  const LoadedModel loaded = testing::loaded_from_text(oscillator(1.0, ", integrator: auto, dt: 1.0"));
  const RunOutcome outcome = testing::simulate(loaded, 0.1);
  INFO(outcome.stats.hand_over_reason);
  CHECK(outcome.stats.handed_over_at < 0.0);
  CHECK_THAT(outcome.stats.hand_over_reason,
             Catch::Contains("Euler cannot run this model") && Catch::Contains("above the stability limit"));
}

TEST_CASE("a model that names no integrator runs with auto and a model may name it", "[integrators][auto][model_io]") {
  CHECK(testing::loaded_from_text(oscillator(1.0)).run_spec.simulation.integrator == IntegratorKind::Auto);
  CHECK(testing::loaded_from_text(oscillator(1.0, ", integrator: auto")).run_spec.simulation.integrator == IntegratorKind::Auto);
  CHECK(testing::loaded_from_text(oscillator(1.0, ", integrator: euler")).run_spec.simulation.integrator == IntegratorKind::Euler);
  CHECK_THROWS_WITH(testing::model_from_text(oscillator(1.0, ", integrator: rk4")),
                    Catch::Contains("integrator must be auto, ida or euler, not 'rk4'"));
  for (const IntegratorKind kind : {IntegratorKind::Ida, IntegratorKind::Euler, IntegratorKind::Auto})
    CHECK(integrator_from_name(integrator_name(kind)) == kind);
}

TEST_CASE("IDA runs a unit whose only forces at t = 0 are round-off: they set no tolerance scale", "[integrators][ida]") {
  // No force acts at t = 0 but round-off (2e-8 N: draft gears whose points sit 1e-16 m inside
  // their free length). Taken as the force scale, it gave the multipliers a tolerance of 2e-12 N
  // and IDA stopped with IDA_CONV_FAIL at 4.5 ms (d2514da); the kinetic scale now takes over.
  // x-momentum, 81,700 kg x 12 m/s, has no outside force to change it. (To 50 ms: at 52 ms
  // the unit's 2 cm coupler spring is compressed through and the run stops there, by design.)
  const std::string file = source_path("tests/robustness/models/stiff_anticlimber_unit.yaml");
  const LoadedModel loaded = load_model(file, {"simulation.integrator=ida", "simulation.t_end=0.05"});
  const Model& model = loaded.model;
  DaeSystem system(model);
  SampleTimes samples;
  const RunOutcome outcome = make_integrator(system, loaded.run_spec.simulation)->run(0.05, 0.001, samples);
  INFO(outcome.message);
  REQUIRE(outcome.ok);
  double momentum = 0.0;  // [kg m/s]
  for (std::size_t b = 0; b < model.bodies().size(); ++b)
    momentum += model.bodies()[b].mass * outcome.y[3 * model.body_count() + 3 * b];
  CHECK(momentum == Approx((41000.0 + 900.0 + 900.0 + 38000.0 + 900.0) * 12.0).epsilon(1e-9));
}

TEST_CASE("auto hands a run IDA fails on to Euler from IDA's last good state and says so", "[integrators][auto]") {
  // An absolute length tolerance of 1e-16 m, below the round-off of the model's 42 m
  // coordinates: IDA stops with IDA_ERR_FAIL at the first contact (1.67 ms).
  // No force from outside acts (no gravity, no ground element): the x-momentum of the bodies,
  // 81,700 kg x 12 m/s for the moving unit, stays what it was through IDA's part, the hand-over
  // and Euler's part (Euler's internal forces are equal and opposite at every step).
  const std::string file = source_path("tests/robustness/models/stiff_anticlimber_unit.yaml");
  const LoadedModel ida_loaded = load_model(file, {"simulation.integrator=ida", "simulation.t_end=0.05", "simulation.atol=1e-16"});
  const Model& ida_model = ida_loaded.model;
  DaeSystem ida_system(ida_model);
  SampleTimes ida_samples;
  const RunOutcome by_ida = make_integrator(ida_system, ida_loaded.run_spec.simulation)->run(0.05, 0.001, ida_samples);
  REQUIRE_FALSE(by_ida.ok);
  CHECK_THAT(by_ida.message, Catch::Contains("IDA_ERR_FAIL"));
  // "IDA failed at t = T with ...": auto's IDA takes the same steps up to T.
  const std::size_t at = by_ida.message.find("IDA failed at t = ");
  REQUIRE(at != std::string::npos);
  const double t_failed = std::stod(by_ida.message.substr(at + 18));

  const LoadedModel auto_loaded = load_model(file, {"simulation.integrator=auto", "simulation.t_end=0.05", "simulation.atol=1e-16"});
  const Model& auto_model = auto_loaded.model;
  DaeSystem auto_system(auto_model);
  SampleTimes auto_samples;
  const RunOutcome outcome = make_integrator(auto_system, auto_loaded.run_spec.simulation)->run(0.05, 0.001, auto_samples);
  INFO(outcome.message);
  INFO(outcome.stats.hand_over_reason);
  REQUIRE(outcome.ok);
  CHECK(outcome.t_reached == Approx(0.05));
  CHECK_THAT(outcome.stats.hand_over_reason, Catch::StartsWith("IDA failed; Euler") && Catch::Contains("IDA_ERR_FAIL"));
  CHECK(outcome.stats.handed_over_at == Approx(t_failed).epsilon(1e-5));
  CHECK(outcome.stats.handed_over_at > by_ida.t_reached);  // after IDA's last sample
  double momentum = 0.0;  // [kg m/s]
  for (std::size_t b = 0; b < auto_model.bodies().size(); ++b)
    momentum += auto_model.bodies()[b].mass * outcome.y[3 * auto_model.body_count() + 3 * b];
  CHECK(momentum == Approx((41000.0 + 900.0 + 900.0 + 38000.0 + 900.0) * 12.0).epsilon(1e-9));
}

namespace {

// A 1 kg ball dropped 5 cm onto a damped floor (1e5 N/m, 20 N s/m): ten bounces in 2 s. Under
// Euler at its 1 ms step the damper's work is far off (the floor's dissipation 1.73 J against
// 0.489 J: 55.6 % of the energy turned over created).
std::string bouncing_ball(const std::string& integrator) {
  return "railcrash: 1\nname: ball\nunits: SI\ngravity: [0, -9.81]\nbodies:\n"
         "  - {name: ball, mass: 1.0, inertia: 0.01, position: [0, 0.05]}\nelements:\n"
         "  - {name: floor, type: contact, stiffness: 1.0e5, damping: 20, friction: 0, line_point: [0, 0], "
         "line_normal: [0, 1], points: [{body: ball, at: [0, 0]}]}\n"
         "simulation: {t_end: 2.0, output_interval: 0.01, dt: 1.0e-3, integrator: " + integrator + "}\n";
}

// A 1 m pendulum, 2 kg at its tip, pinned to the ground and released horizontal.
std::string pendulum(double t_end) {
  std::ostringstream s;
  s << "railcrash: 1\nname: pendulum\nunits: SI\ngravity: [0, -9.81]\nbodies:\n"
    << "  - {name: bob, mass: 2.0, inertia: 0.01, position: [1, 0]}\nelements:\n"
    << "  - {name: pin, type: pin_joint, points: [{body: ground, at: [0, 0]}, {body: bob, at: [-1, 0]}]}\n"
    << "simulation: {t_end: " << t_end << ", rtol: 1e-8, dt: 1e-4}\n";
  return s.str();
}

}  // namespace

TEST_CASE("IDA takes the run back from an Euler whose energy drifts past half the warnings' limit", "[integrators][auto]") {
  const RunOutcome by_ida = testing::simulate(testing::loaded_from_text(bouncing_ball("ida")));
  const RunOutcome by_euler = testing::simulate(testing::loaded_from_text(bouncing_ball("euler")));
  const RunOutcome by_auto = testing::simulate(testing::loaded_from_text(bouncing_ball("auto")));
  REQUIRE(by_ida.ok);
  REQUIRE(by_euler.ok);
  REQUIRE(by_auto.ok);
  INFO(by_auto.stats.hand_over_reason);
  // IDA hands the ball to Euler after its first bounces and takes it back within the next ones.
  REQUIRE(by_auto.stats.handed_over_at > 0.0);
  REQUIRE(by_auto.stats.handed_back_at > by_auto.stats.handed_over_at);
  CHECK(by_auto.stats.handed_back_at < 0.5);
  CHECK_THAT(by_auto.stats.hand_over_reason,
             Catch::Contains("IDA took the run back at t = ") && Catch::Contains("of the energy turned over since (more than 0.5 %)"));
  const auto dissipated = [](const RunOutcome& o) { return EnergyBalance::between(o.initial_energy, o.final_energy).dissipated; };
  const auto share = [](const RunOutcome& o) {
    const EnergyBalance b = EnergyBalance::between(o.initial_energy, o.final_energy);
    return std::abs(b.integration_drift()) / b.turned_over();
  };
  // Euler alone: the floor's dissipation several times IDA's, its drift over the warnings' 1 %.
  CHECK(dissipated(by_euler) > 3.0 * dissipated(by_ida));
  CHECK(share(by_euler) > 0.3);
  // auto: IDA's dissipation within the 0.5 % Euler was allowed (and a little of the ball's
  // remaining energy), and its drift within the warnings' limit.
  CHECK(dissipated(by_auto) == Approx(dissipated(by_ida)).epsilon(0.01));
  CHECK(share(by_auto) < 0.01);
  // The counters of all three parts: IDA's steps before and after, Euler's 1 ms steps between.
  CHECK(by_auto.stats.steps > static_cast<long>((by_auto.stats.handed_back_at - by_auto.stats.handed_over_at) / 1e-3));
  CHECK(by_auto.stats.last_step != 1e-3);  // IDA's, ending the run
  // With one output sample, at t_end, Euler checks itself every 50 of its steps instead.
  const RunOutcome one_row = testing::simulate(testing::loaded_from_text(bouncing_ball("auto")), 2.0);
  REQUIRE(one_row.ok);
  INFO(one_row.stats.hand_over_reason);
  CHECK(one_row.stats.handed_over_at == by_auto.stats.handed_over_at);
  REQUIRE(one_row.stats.handed_back_at > one_row.stats.handed_over_at);
  CHECK(one_row.stats.handed_back_at < 0.5);
  CHECK(dissipated(one_row) == Approx(dissipated(by_ida)).epsilon(0.01));
}

namespace {

/// The pendulum under auto handed to Euler at the first chance and taken back once its penalty
/// joint opens at all (1e-12 m; the energy limit set aside: early on the swing turns over little
/// energy), checked every check_steps Euler steps and at each sample.
RunOutcome pendulum_taken_back(DaeSystem& system, const LoadedModel& loaded, const IdaSettings& ida, double t_end,
                               long check_steps, SampleTimes& samples) {
  AutoSettings rule = hand_over_at_first_chance();
  rule.require_closed_joints = false;
  rule.euler_joint_opening = 1e-12;  // [m]
  rule.euler_energy_share = 1.0;
  rule.euler_check_steps = check_steps;
  AutoIntegrator integrator(system, ida, euler_settings(loaded.run_spec.simulation), rule);
  const RunOutcome outcome = integrator.run(t_end, 0.01, samples);
  INFO(outcome.message);
  INFO(outcome.stats.hand_over_reason);
  REQUIRE(outcome.ok);
  REQUIRE(outcome.stats.handed_over_at > 0.0);
  CHECK_THAT(outcome.stats.hand_over_reason, Catch::Contains("its penalty joints opened by"));
  return outcome;
}

}  // namespace

TEST_CASE("IDA takes a run back from Euler's open penalty joints, closes them and goes on with the motion", "[integrators][auto]") {
  const double t_end = 1.0;  // [s]
  const LoadedModel loaded = testing::loaded_from_text(pendulum(t_end));
  DaeSystem ida_system(loaded.model);
  IdaSettings ida = ida_settings(loaded.run_spec.simulation);
  SampleTimes a;
  const RunOutcome by_ida = IdaIntegrator(ida_system, ida).run(t_end, 0.01, a);
  REQUIRE(by_ida.ok);

  DaeSystem system(loaded.model);
  SampleTimes samples;
  const RunOutcome outcome = pendulum_taken_back(system, loaded, ida, t_end, 50, samples);
  // Taken back at Euler's first check: its 50th step (before the first sample, at 0.01 s).
  CHECK(outcome.stats.handed_back_at > outcome.stats.handed_over_at);
  CHECK(outcome.stats.handed_back_at == Approx(outcome.stats.handed_over_at + 50 * 1e-4).epsilon(1e-9));
  REQUIRE(samples.times.size() == 101);
  // IDA closed the joint and went on: the bob 1 m from the pin, and where IDA alone has it,
  // within what a few Euler steps of 1e-4 s (omega dt ~ 3e-4) can move it.
  const double x = outcome.y[0], y = outcome.y[1];
  CHECK(outcome.max_constraint_residual < 1e-3);
  const double theta = std::atan2(y, x), theta_ida = std::atan2(by_ida.y[1], by_ida.y[0]);
  CHECK(theta == Approx(theta_ida).margin(1e-3));
  // The bob's centre is its point 1 m from the pin: |r| = 1 after IDA's assembly closed the joint.
  CHECK(std::hypot(x, y) == Approx(1.0).epsilon(1e-8));
  // The energy the pendulum holds: Euler's few steps and the joint's closing changed it little.
  const EnergyBalance b = EnergyBalance::between(outcome.initial_energy, outcome.final_energy);
  CHECK(std::abs(b.integration_drift()) < 1e-3 * std::abs(b.turned_over()));
}

TEST_CASE("a sample where Euler's joints stand open is not written: IDA takes the run back before it", "[integrators][auto]") {
  // The trial checks before the step's end is sampled: the open state is never an output row
  // (emu_two_car_crush_zones at rtol 1e-3 wrote a 2.02 mm opening at one sample, with a
  // warning, before IDA took that run back).
  const double t_end = 0.1;  // [s]
  const LoadedModel loaded = testing::loaded_from_text(pendulum(t_end));
  DaeSystem system(loaded.model);
  SampleTimes samples;  // checks at the samples alone
  const RunOutcome outcome =
      pendulum_taken_back(system, loaded, ida_settings(loaded.run_spec.simulation), t_end, 1000000, samples);
  // Taken back at the first sample after the hand-over: the end of Euler's step past 0.01 s.
  CHECK(outcome.stats.handed_back_at == Approx(0.01).margin(1e-4));
  REQUIRE(samples.times.size() == 11);
  // Every sample has the joint closed to IDA's tolerance: the one at 0.01 s is IDA's, from the
  // state it closed. Euler's stood open by 6.1e-7 m there (hand_over_reason), and was written
  // there before the trial was asked first.
  CHECK(outcome.max_constraint_residual < 1e-8);
}

TEST_CASE("auto keeps IDA where Euler's penalty joints would stand open under the joints' loads", "[integrators][auto]") {
  // The pendulum's pin carries its bob's weight and swing (IDA's multipliers, up to 3 m g): with
  // Euler's penalty stiffness k the pin would stand open by |lambda| / k, more than a limit of
  // 1e-12 m as soon as it carries anything. The same rule with the check off hands over.
  const double t_end = 0.2;  // [s]
  const LoadedModel loaded = testing::loaded_from_text(pendulum(t_end));
  AutoSettings rule = hand_over_at_first_chance();
  rule.euler_joint_opening = 1e-12;  // [m]
  for (const bool check : {true, false}) {
    INFO("require_closed_joints " << check);
    rule.require_closed_joints = check;
    DaeSystem system(loaded.model);
    AutoIntegrator integrator(system, ida_settings(loaded.run_spec.simulation), euler_settings(loaded.run_spec.simulation), rule);
    SampleTimes samples;
    const RunOutcome outcome = integrator.run(t_end, 0.01, samples);
    INFO(outcome.stats.hand_over_reason);
    REQUIRE(outcome.ok);
    if (check) {
      CHECK(outcome.stats.handed_over_at < 0.0);
      CHECK_THAT(outcome.stats.hand_over_reason, Catch::Contains("Euler's penalty joints would stand open by"));
    } else {
      CHECK(outcome.stats.handed_over_at > 0.0);
    }
  }
}
