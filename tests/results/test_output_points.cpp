// Output points (`outputs:` in the model file): position, velocity and acceleration of points
// on bodies in timeseries.csv, against rigid-body kinematics and a pinned point at rest.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <unistd.h>

#include "railcrash/core/error.hpp"
#include "railcrash/model/model_io.hpp"
#include "railcrash/results/run.hpp"

namespace fs = std::filesystem;

namespace {

/// timeseries.csv as columns by name.
std::map<std::string, std::vector<double>> read_columns(const fs::path& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);  // the run's provenance
  std::getline(in, line);
  std::vector<std::string> names;
  std::stringstream header(line);
  for (std::string name; std::getline(header, name, ',');) names.push_back(name);
  std::map<std::string, std::vector<double>> columns;
  while (std::getline(in, line)) {
    std::stringstream row(line);
    std::string value;
    for (std::size_t k = 0; k < names.size() && std::getline(row, value, ','); ++k) columns[names[k]].push_back(std::stod(value));
  }
  return columns;
}

fs::path run_text(const std::string& yaml, const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("railcrash_outputs_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const railcrash::LoadedModel loaded = railcrash::load_model_text(yaml, "outputs.yaml");
  const railcrash::Model& model = loaded.model;
  REQUIRE(railcrash::run_model(model, loaded.run_spec, dir.string()).outcome.ok);
  return dir;
}

}  // namespace

TEST_CASE("Output points on a spinning free body follow rigid-body kinematics", "[outputs]") {
  // omega = 3 rad/s, v = (1, 0), no forces: r = (t, 0) + R(3t) s, v = (1, 0) + 3 (-(R s)_y, (R s)_x), a = -9 R s.
  const std::string yaml =
      "railcrash: 1\nname: spin\nunits: SI\ngravity: [0, 0]\n"
      "bodies:\n  - {name: wheel, mass: 2, inertia: 0.5, position: [0, 0], velocity: [1, 0], angular_velocity: 3}\n"
      "outputs:\n  - {name: tip, body: wheel, at: [0.4, 0.1]}\n  - {body: wheel, at: [0, 0], quantities: [acceleration]}\n";
  const std::string simulation = GENERATE(std::string("simulation: {t_end: 1, rtol: 1.0e-10, output_interval: 0.01}\n"),
                                          std::string("simulation: {t_end: 1, integrator: euler, dt: 0.001, output_interval: 0.01}\n"));
  INFO(simulation);
  const fs::path dir = run_text(yaml + simulation, "spin");
  const auto c = read_columns(dir / "timeseries.csv");
  REQUIRE(c.count("tip.x") == 1);
  REQUIRE(c.count("wheel_point2.ax") == 1);  // the default name
  CHECK(c.count("wheel_point2.x") == 0);      // only what was asked
  const std::vector<double>& t = c.at("t");
  REQUIRE(t.size() == 101);
  for (std::size_t k = 0; k < t.size(); ++k) {
    const double th = 3.0 * t[k], rx = 0.4 * std::cos(th) - 0.1 * std::sin(th), ry = 0.4 * std::sin(th) + 0.1 * std::cos(th);
    CHECK(c.at("tip.x")[k] == Approx(t[k] + rx).margin(1e-7));
    CHECK(c.at("tip.y")[k] == Approx(ry).margin(1e-7));
    CHECK(c.at("tip.vx")[k] == Approx(1.0 - 3.0 * ry).margin(1e-6));
    CHECK(c.at("tip.vy")[k] == Approx(3.0 * rx).margin(1e-6));
    CHECK(c.at("tip.ax")[k] == Approx(-9.0 * rx).margin(1e-5));
    CHECK(c.at("tip.ay")[k] == Approx(-9.0 * ry).margin(1e-5));
    CHECK(c.at("wheel_point2.ax")[k] == Approx(0.0).margin(1e-9));
  }
  fs::remove_all(dir);
}

TEST_CASE("The pinned point of a pendulum stays at rest: its acceleration from IDA's multipliers is zero", "[outputs]") {
  // A bar of 1 kg, centroidal inertia 0.1, pinned at its end [-1, 0] to the ground, released
  // horizontal: the centre accelerates at up to about g; the pin's point must not.
  const std::string yaml =
      "railcrash: 1\nname: pendulum\nunits: SI\n"
      "bodies:\n  - {name: bar, mass: 1, inertia: 0.1, position: [1, 0]}\n"
      "elements:\n  - {name: pin, type: pin_joint, points: [{body: ground, at: [0, 0]}, {body: bar, at: [-1, 0]}]}\n"
      "outputs:\n  - {name: pivot, body: bar, at: [-1, 0]}\n  - {name: end, body: bar, at: [1, 0], quantities: [acceleration]}\n"
      "simulation: {t_end: 1, rtol: 1.0e-8, output_interval: 0.01}\n";
  const fs::path dir = run_text(yaml, "pendulum");
  const auto c = read_columns(dir / "timeseries.csv");
  double largest_pivot = 0.0, largest_end = 0.0;
  for (std::size_t k = 0; k < c.at("t").size(); ++k) {
    CHECK(std::hypot(c.at("pivot.x")[k], c.at("pivot.y")[k]) < 1e-6);
    CHECK(std::hypot(c.at("pivot.vx")[k], c.at("pivot.vy")[k]) < 1e-5);
    largest_pivot = std::max(largest_pivot, std::hypot(c.at("pivot.ax")[k], c.at("pivot.ay")[k]));
    largest_end = std::max(largest_end, std::hypot(c.at("end.ax")[k], c.at("end.ay")[k]));
  }
  CHECK(largest_pivot < 1e-4 * 9.81);
  // At the start the bar's free end accelerates at 2 x the centre's: a_c = g m l^2 / (J + m l^2) = 9.81 / 1.1.
  CHECK(c.at("end.ay")[0] == Approx(-2.0 * 9.80665 / 1.1).epsilon(1e-6));
  CHECK(largest_end > 9.81);
  fs::remove_all(dir);
}

TEST_CASE("Output requests that are wrong are refused with file, line and what to change", "[outputs]") {
  const std::string head = "railcrash: 1\nname: x\nunits: SI\nbodies:\n  - {name: bob, mass: 1, inertia: 1, position: [0, 0]}\noutputs:\n  - ";
  const std::string tail = "\nsimulation: {t_end: 1}\n";
  const auto message = [&](const std::string& item) {
    try {
      railcrash::load_model_text(head + item + tail, "outputs.yaml");
    } catch (const railcrash::InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CHECK_THAT(message("{body: bobb}"), Catch::Contains("outputs.yaml:7") && Catch::Contains("unknown body 'bobb'") && Catch::Contains("bob"));
  CHECK_THAT(message("{body: ground}"), Catch::Contains("the ground does not move"));
  CHECK_THAT(message("{body: bob, quantities: [jerk]}"), Catch::Contains("unknown quantity 'jerk'"));
  CHECK_THAT(message("{name: bob, body: bob}"), Catch::Contains("already a body, element or output"));
  CHECK_THAT(message("{body: bob, colour: red}"), Catch::Contains("unknown key 'colour'"));
}
