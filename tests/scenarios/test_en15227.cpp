// EN 15227 scenarios generated from the report's car: structure, bad input, and two physical
// checks on short runs (mirror symmetry of scenario 1, momentum in scenario 2).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>

#include "railcrash/core/error.hpp"
#include "railcrash/model/model_io.hpp"
#include "railcrash/results/run.hpp"
#include "railcrash/results/scenario_criteria.hpp"
#include "railcrash/scenarios/en15227.hpp"
#include "railcrash/solver/dae_system.hpp"
#include "requests.hpp"
#include "support.hpp"

using namespace railcrash;

namespace {

const std::string kTrain = std::string(RAILCRASH_SOURCE_DIR) + "/models/report/final_two_car.yaml";

ScenarioRequest report_car(int number) {
  ScenarioRequest q = testing::example_request(number, kTrain);
  q.passenger_bodies = {"center_body"};
  q.survival_gauge = {"bolster_body", "rear_body"};
  q.buffer_curve = {{0.0, 0.0}, {105.0, 1000.0}, {150.0, 2000.0}};
  q.buffer_unloading_stiffness = 50.0;
  q.buffer_height = 1060.0;
  return q;
}

const Body& body_named(const Model& model, const std::string& name) {
  return model.bodies()[static_cast<std::size_t>(*model.find_body(name))];
}

std::string error_of(const ScenarioRequest& q) {
  try {
    make_scenario_model(q);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

/// Runs the model (IDA, in memory, output every `interval`) and returns the run with its columns by name.
struct Run {
  RunReport report;
  std::map<std::string, std::size_t> column;
  const std::vector<double>& operator[](const std::string& name) const { return report.series[column.at(name)]; }
};
Run run_in_memory(LoadedModel& loaded, double interval) {
  loaded.run_spec.simulation.output_interval = interval;
  Run run{run_model(loaded.model, loaded.run_spec, "", nullptr, false, true), {}};
  REQUIRE(run.report.outcome.ok);
  for (std::size_t k = 0; k < run.report.columns.size(); ++k) run.column[run.report.columns[k]] = k;
  return run;
}

/// The wagon has taken up momentum (the collision happened) and the total longitudinal momentum
/// has not changed (measured 5e-12 of the initial in the report car's scenario 2, verify.sh).
void check_momentum_through_the_collision(const Model& model, const Run& run) {
  const auto momentum = [&](std::size_t sample) {
    double p = 0.0;
    for (const Body& b : model.bodies()) p += b.mass * run[b.name + ".vx"][sample];
    return p;
  };
  const std::size_t last = run["t"].size() - 1;
  CHECK(body_named(model, "wagon").mass * run["wagon.vx"][last] > 0.05 * momentum(0));
  CHECK(std::abs(momentum(last) - momentum(0)) <= 1e-9 * momentum(0));
}

}  // namespace

TEST_CASE("scenario 1: two identical trains, mirrored, the standing one raised by the offset", "[scenario]") {
  ScenarioRequest q = report_car(1);
  q.cars = 2;
  const LoadedModel loaded = load_model_text(make_scenario_model(q), "scenario1.yaml");
  const Model& model = loaded.model;
  REQUIRE(loaded.run_spec.scenario);
  CHECK(model.body_count() == 4 * 9);
  const double offset = 40.0 / 25.4;         // [in]
  const double half_speed = 36.0 / 3.6 / 0.0254 / 2.0;  // [in/s] 393.7 / 2
  CHECK(loaded.run_spec.scenario->closing_speed == Approx(393.700787));
  for (const char* part : {"coupler", "front_end", "center_body", "rear_body", "front_truck"})
    for (const char* car : {"1_", "2_"}) {
      const Body& s = body_named(model, std::string("s") + car + part);
      const Body& t = body_named(model, std::string("t") + car + part);
      CHECK(t.mass == s.mass);  // the loaded striking car on both sides
      CHECK(t.inertia == s.inertia);
      CHECK(t.x == Approx(-s.x).margin(1e-9));
      CHECK(t.y == Approx(s.y + offset).margin(1e-9));
      CHECK(s.vx == Approx(half_speed));
      CHECK(t.vx == Approx(-half_speed));
    }
  // 5 g in in/s^2 (standard gravity 386.088 in/s^2, as results.hpp's peaks in g).
  CHECK(loaded.run_spec.scenario->deceleration_limit == Approx(5.0 * 386.088));
  CHECK(loaded.run_spec.scenario->survival_gauges.size() == 4);
  CHECK(loaded.run_spec.scenario->wheels == std::vector<std::string>{"s1_front_truck_wheel_1", "s1_front_truck_wheel_2",
                                                           "t1_front_truck_wheel_1", "t1_front_truck_wheel_2"});
  CHECK(loaded.run_spec.scenario->interface_element == "anticlimber");
}

TEST_CASE("scenario 2: the train into an 80 t wagon with side buffers", "[scenario]") {
  const LoadedModel loaded = load_model_text(make_scenario_model(report_car(2)), "scenario2.yaml");
  const Model& model = loaded.model;
  const Body& wagon = body_named(model, "wagon");
  CHECK(wagon.mass * 386.088 == Approx(80000.0 / 0.45359237));  // weight 176,370 lbf
  CHECK(wagon.vx == 0.0);
  CHECK(body_named(model, "s1_center_body").vx == Approx(393.700787));
  CHECK_FALSE(model.find_body("t1_center_body"));
  CHECK(loaded.run_spec.scenario->interface_bodies == std::vector<std::string>{"s1_front_end", "wagon"});
}

TEST_CASE("scenario: bad requests name what is missing", "[scenario]") {
  ScenarioRequest q = report_car(1);
  q.offset.reset();
  CHECK_THAT(error_of(q), Catch::Contains("missing --offset"));
  q = report_car(1);
  q.category = "C-V";
  CHECK_THAT(error_of(q), Catch::Contains("not an EN 15227 crashworthiness design category"));
  q = report_car(1);
  q.category = "C-III";
  CHECK_THAT(error_of(q), Catch::Contains("missing --speed"));
  q = report_car(5);
  CHECK_THAT(error_of(q), Catch::Contains("defines scenarios 1 to 4"));
  CHECK_THAT(error_of(report_car(4)), Catch::Contains("out of the longitudinal-vertical plane"));
  q = report_car(2);
  q.buffer_curve.clear();
  CHECK_THAT(error_of(q), Catch::Contains("missing --buffer-curve"));
  q = report_car(2);
  q.buffer_unloading_stiffness = 20.0;  // the curve's second segment rises at 1000 / 45 = 22.2 kN/mm
  CHECK_THAT(error_of(q), Catch::Contains("below the curve's steepest slope 22.2222 kN/mm"));
  q = report_car(1);
  q.train_path = std::string(RAILCRASH_SOURCE_DIR) + "/models/examples/coupled_cars.yaml";
  CHECK_THAT(error_of(q), Catch::Contains("coupled_cars.yaml"));
}

TEST_CASE("scenario 1 without offset is mirror-symmetric: the interface does not move", "[scenario]") {
  // Until 9 ms: the coupler faces meet at 7.1 ms and the rail hangers and draft gears change mode,
  // all in mirrored pairs, which IDA locates up to 1e-13 s apart. Where the first of a pair
  // restarts IDA, the second may change within the first step after it without a restart, its
  // lag being within the local tolerance (IdaIntegrator::advance, lag_within_tolerance): the two
  // trains then differ by a part of the local tolerance, rtol of the closing speed, not by
  // round-off. Measured: 1.4e-7 of the closing speed (0.014 rtol) from the rail hangers'
  // "extension segment 1" at 8.08 ms in this 9 ms run; 2.5e-12 up to 9.5 ms in verify.sh's
  // 20 ms run, whose steps differ. At the anticlimber's contact (9.88 ms) the trains start to
  // drift apart, 4.8e-7 of the closing speed at 10 ms and 1.19e-3 at 20 ms, at any rtol: the
  // anticlimber measures its vertical offset in body 1's axes, which is not mirror-symmetric
  // (models/scenarios/verify.sh prints it).
  ScenarioRequest q = report_car(1);
  q.offset = 0.0;
  q.t_end = 0.009;
  LoadedModel loaded = load_model_text(make_scenario_model(q), "symmetric.yaml");
  Model& model = loaded.model;
  const Run run = run_in_memory(loaded, 0.0005);
  const double closing_speed = loaded.run_spec.scenario->closing_speed;
  double velocity_difference = 0.0, position_difference = 0.0;  // [in/s], [in] of mirrored bodies
  for (const Body& b : model.bodies()) {
    if (b.name[0] != 's') continue;
    const std::string mirror = "t" + b.name.substr(1);
    for (const char* axis : {".vx", ".x"}) {
      const auto& s = run[b.name + axis];
      const auto& t = run[mirror + axis];
      double& largest = axis[1] == 'v' ? velocity_difference : position_difference;
      for (std::size_t k = 0; k < s.size(); ++k) largest = std::max(largest, std::abs(s[k] + t[k]));
    }
  }
  const double rtol = loaded.run_spec.simulation.rtol;
  CHECK(velocity_difference <= 0.1 * rtol * closing_speed);
  CHECK(position_difference <= 0.1 * rtol * closing_speed * *q.t_end);
  // The collision did happen: the lead couplers have bounced back off each other.
  const auto& coupler_vx = run["s1_coupler.vx"];
  CHECK(*std::min_element(coupler_vx.begin(), coupler_vx.end()) < 0.0);
}

TEST_CASE("scenario 2 conserves the longitudinal momentum", "[scenario]") {
  ScenarioRequest q = report_car(2);
  q.t_end = 0.03;
  LoadedModel loaded = load_model_text(make_scenario_model(q), "momentum.yaml");
  const Model& model = loaded.model;
  const Run run = run_in_memory(loaded, 0.001);
  check_momentum_through_the_collision(model, run);
  const std::size_t last = run["t"].size() - 1;

  // The criteria in summary.json against the same quantities computed here from the time series.
  const auto summary_value = [&](const std::string& criterion, const std::string& subject) {
    const std::regex pattern("\"criterion\": \"" + criterion + "\", \"subject\": \"" + subject + "\", \"value\": ([-0-9.eE+]+)");
    std::smatch match;
    REQUIRE(std::regex_search(run.report.summary_json, match, pattern));
    return std::stod(match[1]);
  };
  double shortening = 0.0, lift = 0.0, vertical_change = 0.0;  // [in]
  const auto gauge = [&](std::size_t k) {
    return std::hypot(run["s1_bolster_body.x"][k] - run["s1_rear_body.x"][k], run["s1_bolster_body.y"][k] - run["s1_rear_body.y"][k]);
  };
  const auto relative_height = [&](std::size_t k) { return run["wagon.y"][k] - run["s1_front_end.y"][k]; };
  for (std::size_t k = 0; k <= last; ++k) {
    shortening = std::max(shortening, gauge(0) - gauge(k));
    lift = std::max(lift, -run["s1_front_truck_wheel_1.penetration"][k]);
    vertical_change = std::max(vertical_change, std::abs(relative_height(k) - relative_height(0)));
  }
  CHECK(shortening > 0.0);
  CHECK(summary_value("survival_gauge", "s1") == Approx(shortening).epsilon(1e-9));
  CHECK(summary_value("wheel_lift", "s1_front_truck_wheel_1") == Approx(lift).epsilon(1e-9).margin(1e-12));
  CHECK(summary_value("override", "s1_front_end / wagon") == Approx(vertical_change).epsilon(1e-9));
}

namespace {

const std::string kBarrierCars = std::string(RAILCRASH_SOURCE_DIR) + "/models/barrier/two_car_barrier.yaml";

/// The barrier test's two cars as a scenario train (models/scenarios/make.sh's inputs).
ScenarioRequest barrier_cars(int number) {
  ScenarioRequest q = report_car(number);
  q.train_path = kBarrierCars;
  q.passenger_bodies = {"lead_body", "trail_body"};
  q.survival_gauge.clear();
  q.face_stiffness = 875.6;
  q.face_height = 304.8;
  q.face_friction = 0.3;
  return q;
}

const Element* element_named(const Model& model, const std::string& name) {
  for (const auto& e : model.elements())
    if (e->name() == name) return e.get();
  return nullptr;
}

}  // namespace

TEST_CASE("scenario 1 from the barrier test's cars: the striking end found by roles, the unit mirrored", "[scenario]") {
  const Model source = load_model(kBarrierCars).model;
  const LoadedModel loaded = load_model_text(make_scenario_model(barrier_cars(1)), "scenario1_barrier.yaml");
  const Model& model = loaded.model;
  CHECK(model.body_count() == 2 * source.body_count());
  const double offset = 40.0 / 25.4;                    // [in]
  const double half_speed = 36.0 / 3.6 / 0.0254 / 2.0;  // [in/s]
  // The front face is the wall contact's point on lead_front, (0, 40) in the barrier model: x = 0 stays.
  for (const Body& b : source.bodies()) {
    const Body& s = body_named(model, "s_" + b.name);
    const Body& t = body_named(model, "t_" + b.name);
    CHECK(s.mass == b.mass);
    CHECK(t.mass == b.mass);
    CHECK(s.x == Approx(b.x).margin(1e-9));
    CHECK(t.x == Approx(-b.x).margin(1e-9));
    CHECK(t.y == Approx(b.y + offset).margin(1e-9));
    CHECK(s.vx == Approx(half_speed));
    CHECK(t.vx == Approx(-half_speed));
    CHECK(s.car == (b.car.empty() ? "" : "s_" + b.car));
  }
  // The barrier's fixed surfaces are left out; the faces meet at an uncoupled coupler_end.
  CHECK_FALSE(element_named(model, "s_wall"));
  CHECK_FALSE(element_named(model, "s_climb_limit"));
  REQUIRE(element_named(model, "front_faces"));
  CHECK(element_named(model, "front_faces")->type() == "coupler_end");
  CHECK(loaded.run_spec.scenario->interface_bodies == std::vector<std::string>{"s_lead_front", "t_lead_front"});
  CHECK(loaded.run_spec.scenario->wheels == std::vector<std::string>{"s_lead_truck_front_wheel_1", "s_lead_truck_front_wheel_2",
                                                           "t_lead_truck_front_wheel_1", "t_lead_truck_front_wheel_2"});
  CHECK(loaded.run_spec.scenario->survival_cars == std::vector<std::string>{"s_lead", "s_trail", "t_lead", "t_trail"});
  CHECK(loaded.run_spec.scenario->passenger_bodies == std::vector<std::string>{"s_lead_body", "s_trail_body", "t_lead_body", "t_trail_body"});
}

TEST_CASE("scenario 2 from the barrier test's cars: the buffers strike the front crush element's body", "[scenario]") {
  ScenarioRequest q = barrier_cars(2);
  q.t_end = 0.03;
  LoadedModel loaded = load_model_text(make_scenario_model(q), "scenario2_barrier.yaml");
  Model& model = loaded.model;
  CHECK_FALSE(model.find_body("t_lead_body"));
  CHECK(loaded.run_spec.scenario->interface_bodies == std::vector<std::string>{"s_lead_front", "wagon"});
  CHECK(loaded.run_spec.scenario->survival_excluded == std::vector<std::string>{"wagon_buffers"});
  const Element* buffers = element_named(model, "wagon_buffers");
  REQUIRE(buffers);
  // On lead_front (c.g. at x = -30 in) at the face x = 0, 1060 mm above the rail (c.g. at 50 in).
  CHECK(buffers->point(0).body == *model.find_body("s_lead_front"));
  CHECK(buffers->point(0).sx == Approx(30.0));
  CHECK(buffers->point(0).sy == Approx(1060.0 / 25.4 - 50.0));
  const Run run = run_in_memory(loaded, 0.001);
  check_momentum_through_the_collision(model, run);
  const std::size_t last = run["t"].size() - 1;
  // Survival space of the lead car: its own crush elements (the front crush structure and the
  // draft sill), not the wagon's buffers, from the time series by hand.
  double lead_crush = 0.0;  // [in]
  for (std::size_t k = 0; k <= last; ++k)
    lead_crush = std::max(lead_crush, std::max(0.0, run["s_lead_crush.crush"][k]) + std::max(0.0, run["s_lead_draft_sill.crush"][k]));
  const std::regex pattern("\"criterion\": \"survival_space\", \"subject\": \"s_lead\", \"value\": ([-0-9.eE+]+)");
  std::smatch match;
  REQUIRE(std::regex_search(run.report.summary_json, match, pattern));
  CHECK(lead_crush > 0.0);
  CHECK(std::stod(match[1]) == Approx(lead_crush).epsilon(1e-9));
}

TEST_CASE("scenario 3: the train into a deformable obstacle on a slider, no interface", "[scenario]") {
  ScenarioRequest q = barrier_cars(3);
  q.speed = 110.0;
  q.override_limit.reset();  // no interface in scenario 3
  q.obstacle_curve = {{0.0, 0.0}, {100.0, 500.0}, {1000.0, 800.0}};  // test inputs [mm, kN], not the standard's
  q.obstacle_unloading_stiffness = 50.0;
  q.obstacle_height = 1000.0;
  q.t_end = 0.02;
  LoadedModel loaded = load_model_text(make_scenario_model(q), "scenario3_barrier.yaml");
  Model& model = loaded.model;
  const Body& obstacle = body_named(model, "obstacle");
  CHECK(obstacle.mass * 386.088 == Approx(15000.0 / 0.45359237));  // 15 t
  CHECK(body_named(model, "s_lead_body").vx == Approx(110.0 / 3.6 / 0.0254));
  CHECK_FALSE(loaded.run_spec.scenario->has_interface());
  const Run run = run_in_memory(loaded, 0.001);
  CHECK(run.report.summary_json.find("\"criterion\": \"override\"") == std::string::npos);
  CHECK(run.report.summary_json.find("\"criterion\": \"wheel_lift\", \"subject\": \"s_lead_truck_front_wheel_1\"") != std::string::npos);
  CHECK(run["obstacle.vx"].back() > 0.0);  // struck and pushed ahead

  ScenarioRequest missing = q;
  missing.speed.reset();
  CHECK_THAT(error_of(missing), Catch::Contains("missing --speed: scenario 3's speed"));
  missing = q;
  missing.obstacle_curve.clear();
  CHECK_THAT(error_of(missing), Catch::Contains("missing --obstacle-curve"));
  missing = q;
  missing.obstacle_height.reset();
  CHECK_THAT(error_of(missing), Catch::Contains("missing --obstacle-height"));
}

TEST_CASE("scenario: a train model without what the scenario needs is refused naming it", "[scenario]") {
  ScenarioRequest q = barrier_cars(1);
  q.face_stiffness.reset();
  CHECK_THAT(error_of(q), Catch::Contains("missing --face-stiffness"));
  q = barrier_cars(1);  // with the 40 mm offset, frictionless faces would let it do nothing
  q.face_friction.reset();
  CHECK_THAT(error_of(q), Catch::Contains("missing --face-friction"));
  q.offset = 0.0;
  CHECK(error_of(q) == "no error");
  q = barrier_cars(1);
  q.cars = 2;
  CHECK_THAT(error_of(q), Catch::Contains("--cars 2") && Catch::Contains("leave --cars out"));
  q = barrier_cars(2);
  q.crush_zones = {"lead_crsh"};
  CHECK_THAT(error_of(q), Catch::Contains("no element named 'lead_crsh' (from --crush-zones"));
  // Cars declared, but no crush element at the front (two coupled cars with a draft gear).
  q = barrier_cars(1);
  q.train_path = std::string(RAILCRASH_SOURCE_DIR) + "/models/examples/coupled_cars.yaml";
  CHECK_THAT(error_of(q), Catch::Contains("coupled_cars.yaml:") && Catch::Contains("no front end: the scenario needs a crush element"));
  // No car declared at all.
  const std::string path = (testing::temp_path("railcrash_scenario_no_car.yaml")).string();
  std::ofstream(path) << "railcrash: 1\nname: one body\nunits: SI\nbodies:\n  - {name: a, mass: 1000, inertia: 100, position: [0, 1]}\n"
                         "elements: []\nsimulation: {t_end: 0.1}\n";
  q.train_path = path;
  CHECK_THAT(error_of(q), Catch::Contains("no car: a scenario train is built from the cars its bodies declare"));
  std::filesystem::remove(path);
}

TEST_CASE("scenario 1 of the barrier cars without offset is mirror-symmetric through the crush", "[scenario]") {
  // The unit and its mirror image meet at front_faces and crush their lead_crush structures,
  // which unload and reload several times; both integrators keep the two trains mirror images
  // (models/scenarios/verify.sh at 50 ms: IDA 5.1e-12, Euler 3.6e-11 of the closing speed).
  // IDA used to drift to 2.3e-8 at 50 ms: mirrored crush springs changed mode at one time but
  // one was committed 10-20 times (a restart's look-ahead re-committed a spring sitting on the
  // boundary its own commit had just put it on); no element now changes mode twice at one instant.
  const IntegratorKind integrator = GENERATE(IntegratorKind::Ida, IntegratorKind::Euler);
  ScenarioRequest q = barrier_cars(1);
  q.offset = 0.0;
  // Frictionless faces, as without an offset the scenario needs none: the faces' friction
  // (tanh of the vertical slip over 0.01 in/s) turns the round-off difference of the mirrored
  // trains' vertical slip into a force (0.36 in/s apart at 50 ms with IDA at friction 0.3).
  q.face_friction.reset();
  q.t_end = 0.05;
  LoadedModel loaded = load_model_text(make_scenario_model(q), "symmetric_barrier.yaml");
  Model& model = loaded.model;
  loaded.run_spec.simulation.integrator = integrator;
  const Run run = run_in_memory(loaded, 0.0005);
  const double closing_speed = loaded.run_spec.scenario->closing_speed;
  double velocity_difference = 0.0;  // [in/s] of mirrored bodies
  for (const Body& b : model.bodies()) {
    if (b.name.rfind("s_", 0) != 0) continue;
    const auto& s = run[b.name + ".vx"];
    const auto& t = run["t_" + b.name.substr(2) + ".vx"];
    for (std::size_t k = 0; k < s.size(); ++k) velocity_difference = std::max(velocity_difference, std::abs(s[k] + t[k]));
  }
  CHECK(velocity_difference <= 1e-9 * closing_speed);
  // No element changed mode twice at one instant (each lead_crush spring unloads and reloads
  // several times here).
  std::map<std::pair<double, std::string>, int> changes_at;  // (t, element) -> mode changes logged
  int lead_crush_changes = 0;
  for (const EventRecord& e : run.report.outcome.events) {
    if (e.t == 0.0) continue;  // the static settle's initial modes
    if (e.element.find("lead_crush") != std::string::npos) ++lead_crush_changes;
    CHECK(++changes_at[{e.t, e.element}] == 1);
  }
  CHECK(lead_crush_changes >= 8);
  // The collision did happen: the lead cars' front structures have crushed.
  const auto& crush = run["s_lead_crush.crush"];
  CHECK(*std::max_element(crush.begin(), crush.end()) > 1.0);  // [in]
}

TEST_CASE("a survival-space car's crush is the sum of its crush elements at one instant, located events included", "[scenario]") {
  // Scenario 1 of the barrier cars (no excluded element): the leading cars' largest sum of
  // their crush elements' outputs is at a located mode change, where only the changed element's
  // outputs are fresh; the criterion evaluates the car's other crush elements there
  // (car_elements_crush_at): 4.793597 in against the 4.793594 in where every column is fresh.
  // The rows (every output interval) see no more than the criterion, and almost as much. The
  // run summary's car_crush is the car's shortening instead (results.hpp "Car crush").
  LoadedModel loaded = load_model(std::string(RAILCRASH_SOURCE_DIR) + "/models/scenarios/scenario1_barrier_cars.yaml");
  Model& model = loaded.model;
  const Run run = run_in_memory(loaded, loaded.run_spec.simulation.output_interval);
  const DaeSystem system(model);
  for (const CarCrush& car : cars_of(system)) {
    INFO("car " << car.car);
    const std::regex pattern("\"criterion\": \"survival_space\", \"subject\": \"" + car.car + "\", \"value\": ([-0-9.eE+]+)");
    std::smatch match;
    REQUIRE(std::regex_search(run.report.summary_json, match, pattern));
    double rows_max = 0.0;  // [in]
    for (std::size_t k = 0; k < run["t"].size(); ++k) {
      double sum = 0.0;  // [in]
      for (std::size_t e = 0; e < car.columns.size(); ++e)
        sum += car.shares[e] * std::max(0.0, run[system.output_names()[static_cast<std::size_t>(car.columns[e])]][k]);
      rows_max = std::max(rows_max, sum);
    }
    CHECK(rows_max > 3.0);
    CHECK(std::stod(match[1]) >= rows_max - 1e-9);
    CHECK(std::stod(match[1]) == Approx(rows_max).epsilon(1e-3));
  }
}
