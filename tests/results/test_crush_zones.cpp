// Energy absorbed per crush zone and per car (results/crush_zones.hpp), against the area under
// the declared curve computed here on its own.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "railcrash/results/results.hpp"
#include "railcrash/results/run.hpp"
#include "railcrash/solver/dae_system.hpp"
#include "railcrash/solver/integrator.hpp"
#include "support.hpp"

using namespace railcrash;

namespace {

// A 100 t mass at 10 m/s crushes a crush spring against the ground: its speed falls by under
// 0.3 % in 30 ms, so the crush grows at nearly constant speed to about 0.3 m.
// Curve (m, N): (0, 0) (0.02, 200 kN) (0.5, 300 kN) (1.0, 300 kN); unloading 5e7 N/m.
const char* const kPushedCrushSpring =
    "railcrash: 1\nname: pushed\nunits: SI\ngravity: [0, 0]\nbodies:\n"
    "  - {name: block, car: lead, mass: 1.0e5, inertia: 1.0e4, position: [1.0, 0], velocity: [-10, 0]}\n"
    "elements:\n"
    "  - {name: front_zone, type: crush_spring, free_length: 1.0, curve: [[0, 0], [0.02, 2.0e5], [0.5, 3.0e5], [1.0, 3.0e5]], "
    "unloading_stiffness: 5.0e7, points: [{body: ground, at: [0, 0]}, {body: block, at: [0, 0]}]}\n"
    "simulation: {t_end: 0.03, output_interval: 0.001, rtol: 1.0e-8, atol: 1.0e-10}\n";

/// Area under (0, 0) (0.02, 2e5) (0.5, 3e5) (1, 3e5) from 0 to d [J], by hand.
double area_to(double d) {
  if (d <= 0.02) return 0.5 * d * (2.0e5 * d / 0.02);
  const double first = 0.5 * 0.02 * 2.0e5;  // 2000 J
  if (d <= 0.5) {
    const double force = 2.0e5 + (d - 0.02) * (1.0e5 / 0.48);
    return first + 0.5 * (2.0e5 + force) * (d - 0.02);
  }
  return first + 0.5 * (2.0e5 + 3.0e5) * 0.48 + 3.0e5 * (d - 0.5);
}

// Two cars of two bodies; a crush spring in each car and one between them (as test_results.cpp).
const char* const kTwoCars =
    "railcrash: 1\nname: cars\nunits: SI\ngravity: [0, 0]\nbodies:\n"
    "  - {name: striker_rear, car: a, mass: 10, inertia: 1, position: [-2, 0], velocity: [5, 0]}\n"
    "  - {name: striker_end, car: a, mass: 10, inertia: 1, position: [0, 0], velocity: [5, 0]}\n"
    "  - {name: struck_end, car: b, mass: 10, inertia: 1, position: [1, 0]}\n"
    "  - {name: struck_rear, car: b, mass: 10, inertia: 1, position: [3, 0]}\nelements:\n"
    "  - {name: between, type: crush_spring, free_length: 1.0, curve: [[0, 0], [0.01, 1000], [1, 1000]], "
    "unloading_stiffness: 1.0e5, points: [{body: striker_end, at: [0, 0]}, {body: struck_end, at: [0, 0]}]}\n"
    "  - {name: inside, type: crush_spring, free_length: 2.0, curve: [[0, 0], [0.01, 1000], [1, 1000]], "
    "unloading_stiffness: 1.0e5, points: [{body: struck_end, at: [0, 0]}, {body: struck_rear, at: [0, 0]}]}\n"
    "  - {name: striker_spring, type: linear_spring, stiffness: 1.0e4, "
    "points: [{body: striker_rear, at: [0, 0]}, {body: striker_end, at: [0, 0]}]}\n"
    "simulation: {t_end: 0.05, output_interval: 0.001}\n";

std::string file_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

TEST_CASE("a crush spring pushed at nearly constant speed absorbs the area under its curve up to its crush", "[results][crush_zones]") {
  const LoadedModel loaded = testing::loaded_from_text(kPushedCrushSpring);
  const Model& model = loaded.model;
  DaeSystem system(model);
  ResultWriter writer("", system, loaded.run_spec);
  const RunOutcome outcome = make_integrator(system, loaded.run_spec.simulation)->run(0.03, 0.001, writer);
  REQUIRE(outcome.ok);
  const CrushZoneTracker& tracker = writer.crush_zones();
  REQUIRE(tracker.zones().size() == 1);
  const CrushZone& zone = tracker.zones().front();
  CHECK(zone.element == "front_zone");
  CHECK(zone.cars == std::vector<std::string>{"lead"});
  const double crush = 1.0 - outcome.y[0];  // free length - |P2 - P1|, the block at x
  const double speed = -outcome.y[3];
  CHECK(crush == Approx(0.3).epsilon(0.01));  // nearly 10 m/s x 30 ms
  CHECK(speed > 9.9);
  // Still loading on the curve: absorbed = the area to the crush reached.
  CHECK(zone.absorbed == Approx(area_to(crush)).epsilon(1e-6));
  CHECK(zone.peak_absorbed == Approx(zone.absorbed).epsilon(1e-12));
  // The kinetic energy the block lost went into the zone (no other element).
  CHECK(zone.absorbed == Approx(0.5 * 1.0e5 * (100.0 - speed * speed)).epsilon(1e-6));
  // Recoverable: P^2 / (2 unloading_stiffness) at the force on the curve; the rest is dissipated.
  const double force = 2.0e5 + (crush - 0.02) * (1.0e5 / 0.48);
  CHECK(zone.recoverable == Approx(force * force / (2.0 * 5.0e7)).epsilon(1e-6));
  CHECK(zone.dissipated == Approx(zone.absorbed - zone.recoverable).epsilon(1e-12));
  // Capacity: 2000 + 0.48 x 250 kN + 0.5 x 300 kN = 272 kJ.
  REQUIRE(zone.capacity.has_value());
  CHECK(*zone.capacity == Approx(272000.0).epsilon(1e-12));
  const std::vector<CarEnergy> cars = tracker.cars();
  REQUIRE(cars.size() == 1);
  CHECK(cars[0].absorbed == Approx(zone.absorbed).epsilon(1e-12));
  CHECK(cars[0].capacity == Approx(272000.0).epsilon(1e-12));
}

TEST_CASE("a crush zone between two cars counts half for each and the cars add up to the total", "[results][crush_zones]") {
  const LoadedModel loaded = testing::loaded_from_text(kTwoCars);
  const Model& model = loaded.model;
  DaeSystem system(model);
  ResultWriter writer("", system, loaded.run_spec);
  const RunOutcome outcome = make_integrator(system, loaded.run_spec.simulation)->run(0.05, 0.001, writer);
  REQUIRE(outcome.ok);
  const CrushZoneTracker& tracker = writer.crush_zones();
  REQUIRE(tracker.zones().size() == 2);  // the linear spring absorbs by no crushing
  const CrushZone& between = tracker.zones()[0];
  const CrushZone& inside = tracker.zones()[1];
  CHECK(between.cars == std::vector<std::string>{"a", "b"});
  CHECK(between.shares == std::vector<double>{0.5, 0.5});
  CHECK(inside.cars == std::vector<std::string>{"b"});
  CHECK(between.absorbed > 50.0);  // the cars close at 5 m/s: the zone between them crushes
  const std::vector<CarEnergy> cars = tracker.cars();
  REQUIRE(cars.size() == 2);
  CHECK(cars[0].absorbed == Approx(0.5 * between.absorbed).epsilon(1e-12));
  CHECK(cars[1].absorbed == Approx(0.5 * between.absorbed + inside.absorbed).epsilon(1e-12));
  CHECK(cars[0].absorbed + cars[1].absorbed == Approx(tracker.total_absorbed()).epsilon(1e-12));
  // Capacity of each curve: 0.5 x 0.01 x 1000 + 0.99 x 1000 = 995 J.
  CHECK(*between.capacity == Approx(995.0).epsilon(1e-12));
  CHECK(cars[1].capacity == Approx(0.5 * 995.0 + 995.0).epsilon(1e-12));
  // The zones' dissipated energies are the run's dissipated energy (the linear spring
  // dissipates none: its work less its stored energy is the quadrature's drift, 7e-6 J here).
  const EnergyBalance energy = EnergyBalance::between(outcome.initial_energy, outcome.final_energy);
  CHECK(between.dissipated + inside.dissipated == Approx(energy.dissipated).epsilon(1e-6));
}

TEST_CASE("energy_zones.csv and summary.json give the energy per crush zone and per car of one run", "[results][crush_zones]") {
  const auto dir = (testing::temp_path("railcrash_test_energy_zones")).string();
  std::filesystem::remove_all(dir);
  const LoadedModel loaded = testing::loaded_from_text(kPushedCrushSpring);
  const Model& model = loaded.model;
  const RunReport report = run_model(model, loaded.run_spec, dir);
  REQUIRE(report.outcome.ok);
  const std::string summary = file_text(dir + "/summary.json");
  const std::string csv = file_text(dir + "/energy_zones.csv");
  const std::optional<std::string> run = run_id_in(summary);
  REQUIRE(run.has_value());
  CHECK(csv.rfind("# railcrash provenance ", 0) == 0);
  CHECK(run_id_in(csv.substr(0, csv.find('\n'))) == run);
  const double crush = 1.0 - report.outcome.y[0];
  std::istringstream lines(csv);
  std::string line;
  std::getline(lines, line);  // provenance
  std::getline(lines, line);
  CHECK(line == "kind,name,type,cars,absorbed,peak_absorbed,dissipated,recoverable,capacity,share_of_total");
  std::getline(lines, line);
  CHECK(line.rfind("zone,front_zone,crush_spring,lead,", 0) == 0);
  const std::vector<std::string> fields = [&] {
    std::vector<std::string> out;
    std::stringstream row(line);
    for (std::string f; std::getline(row, f, ',');) out.push_back(f);
    return out;
  }();
  REQUIRE(fields.size() == 10);
  CHECK(std::stod(fields[4]) == Approx(area_to(crush)).epsilon(1e-6));
  CHECK(std::stod(fields[8]) == Approx(272000.0).epsilon(1e-12));
  CHECK(fields[9] == "1");
  std::getline(lines, line);
  CHECK(line.rfind("car,lead,,," + fields[4] + ",", 0) == 0);
  CHECK_THAT(summary, Catch::Contains("\"crush_zones\": {") && Catch::Contains("\"element\": \"front_zone\"") &&
                          Catch::Contains("\"capacity\": 272000") && Catch::Contains("\"curve\": {\"deformation\": [0, 0.02, 0.5, 1]"));
  std::filesystem::remove_all(dir);
}
