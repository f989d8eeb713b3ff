// The public interface (api.hpp): results in memory against the files `railcrash run` writes,
// models built in code against the closed form, errors, and runs from several threads.
#include <catch2/catch.hpp>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <regex>
#include <fstream>
#include <sstream>
#include <thread>

#include "railcrash/api.hpp"
#include "railcrash/model/model_io.hpp"
#include "railcrash/results/run.hpp"
#include "support.hpp"
#include <yaml-cpp/yaml.h>

namespace rc = railcrash::api;

namespace {

const std::string kTwoCar = std::string(RAILCRASH_SOURCE_DIR) + "/models/report/final_two_car.yaml";

/// Mean period [s] from the upward crossings of `level` (linear interpolation).
double mean_period(const std::vector<double>& t, const std::vector<double>& x, double level) {
  std::vector<double> crossings;
  for (std::size_t k = 1; k < t.size(); ++k)
    if (x[k - 1] < level && x[k] >= level)
      crossings.push_back(t[k - 1] + (level - x[k - 1]) / (x[k] - x[k - 1]) * (t[k] - t[k - 1]));
  REQUIRE(crossings.size() >= 2);
  return (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
}

rc::ModelBuilder oscillator(double mass, double stiffness) {
  rc::ModelBuilder b("oscillator", "SI");
  b.gravity(0.0, 0.0);
  b.body({"cart", mass, 0.1, 1.1, 0.0});
  b.element("spring", "linear_spring", {{"ground", 0.0, 0.0}, {"cart", 0.0, 0.0}}, {{"stiffness", stiffness}, {"free_length", 1.0}});
  rc::RunSettings s;
  s.t_end = 1.0;
  s.output_interval = 1e-4;
  b.simulation(s);
  return b;
}

/// A free 1 kg body pushed along x by a table force (rows t, Fx, Fy) and run with 1 ms rows:
/// its acceleration is the force, so its CFC peaks are those of the table.
rc::Results pushed_cart(const std::vector<std::array<double, 3>>& force, double t_end, double rtol) {
  rc::ModelBuilder b("pushed cart", "SI");
  b.gravity(0.0, 0.0);
  b.body({"cart", 1.0, 0.1, 0.0, 0.0});
  b.force({"cart", 0.0, 0.0}, force);
  rc::RunSettings s;
  s.t_end = t_end;
  s.output_interval = 1e-3;
  s.rtol = rtol;
  b.simulation(s);
  return rc::run(b.build());
}

std::string read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

TEST_CASE("api: results in memory are the files railcrash run writes", "[api]") {
  const rc::Model model = rc::Model::load(kTwoCar, {"simulation.t_end=0.02"});
  rc::RunSettings settings;
  settings.rtol = 1e-4;
  const rc::Results memory = rc::run(model, settings);
  REQUIRE(memory.ok());

  // The same run through run_model with a folder.
  railcrash::RunOverrides overrides;
  overrides.rtol = 1e-4;
  const railcrash::LoadedModel loaded = railcrash::load_model(kTwoCar, {"simulation.t_end=0.02"}, railcrash::option_settings(overrides));
  const std::string dir =
      (std::filesystem::temp_directory_path() / ("railcrash_api_test_" + std::to_string(::getpid()))).string();
  std::filesystem::remove_all(dir);
  const railcrash::RunReport report = railcrash::run_model(loaded.model, loaded.run_spec, dir);
  REQUIRE(report.outcome.ok);

  std::ifstream csv(dir + "/timeseries.csv");
  std::string header;
  std::getline(csv, header);  // the run's provenance (results/provenance.hpp)
  std::getline(csv, header);
  std::string joined;
  for (const std::string& c : memory.columns) joined += (joined.empty() ? "" : ",") + c;
  CHECK(header == joined);
  CHECK(memory.columns == model.columns());
  std::size_t row = 0;
  for (std::string line; std::getline(csv, line); ++row) {
    std::stringstream cells(line);
    std::size_t column = 0;
    for (std::string cell; std::getline(cells, cell, ','); ++column) {
      REQUIRE(column < memory.values.size());
      REQUIRE(row < memory.values[column].size());
      const double value = memory.values[column][row];
      CHECK(std::stod(cell) == Approx(value).epsilon(1e-11).margin(1e-300));
    }
    CHECK(column == memory.columns.size());
  }
  CHECK(row == memory.t().size());
  CHECK(memory.t().back() == Approx(0.02));
  // Events: one row each, in order.
  std::ifstream events(dir + "/events.csv");
  std::string line;
  std::getline(events, line);  // the run's provenance
  std::getline(events, line);
  std::size_t event_rows = 0;
  while (std::getline(events, line)) ++event_rows;
  CHECK(event_rows == memory.events.size());
  CHECK(memory.events.size() == report.outcome.events.size());
  // summary.json: the same text, but for the run's own wall times.
  const std::string file_summary = read(dir + "/summary.json");
  const auto without_times = [](std::string text) {  // and without the run ids: two runs, two ids
    const auto at = text.find("\"wall_seconds\": ");
    const auto end = text.find(',', at);
    return std::regex_replace(text.erase(at, end - at), std::regex("\"run_id\": \"[0-9a-f]{32}\""), "\"run_id\": \"\"");
  };
  CHECK(without_times(memory.summary_json) == without_times(file_summary));
  REQUIRE(memory.summary.cars.size() == 2);
  CHECK(memory.summary.cars[0].car == "car1");
  CHECK(memory.summary.cars[0].max_crush == Approx(report.car_crush[0].max_crush));
  CHECK(memory.summary.peak_accelerations.size() == 18);
  CHECK(memory.summary.integrator == "ida");
  CHECK(memory.summary.has_responses == report.has_responses);
  std::filesystem::remove_all(dir);
}

TEST_CASE("api: a model built in code oscillates with period 2 pi sqrt(m / k)", "[api]") {
  const rc::Model model = oscillator(2.0, 800.0).build();
  CHECK(model.name() == "oscillator");
  CHECK(model.path().empty());
  CHECK(model.units() == "SI");
  CHECK(model.bodies() == std::vector<std::string>{"cart"});
  rc::RunSettings settings;
  settings.rtol = 1e-9;
  const rc::Results r = rc::run(model, settings);
  REQUIRE(r.ok());
  CHECK(r.t().size() == 10001);
  CHECK(mean_period(r.t(), r.series("cart.x"), 1.0) == Approx(2.0 * M_PI * std::sqrt(2.0 / 800.0)).epsilon(1e-7));
  // A setting on top: 4x the stiffness halves the period; the settings are kept in order.
  const rc::Model stiffer = model.with({"elements.spring.stiffness*=2"}).with({"elements.spring.stiffness*=2"});
  CHECK(stiffer.settings() == std::vector<std::string>{"elements.spring.stiffness*=2", "elements.spring.stiffness*=2"});
  const rc::Results s = rc::run(stiffer, settings);
  CHECK(mean_period(s.t(), s.series("cart.x"), 1.0) == Approx(M_PI * std::sqrt(2.0 / 800.0)).epsilon(1e-7));
  // The builder's YAML is a model file: the same model from text gives the same run.
  const rc::Results again = rc::run(rc::Model::from_yaml(oscillator(2.0, 800.0).yaml()), settings);
  CHECK(again.series("cart.x") == r.series("cart.x"));
}

TEST_CASE("api: a built body may declare its car, and the summary then has that car's crush", "[api]") {
  // A 2 kg cart at 1 m/s into a crush spring on the ground with a 1 N plateau after 1 mm:
  // the crush grows until the plateau has taken the kinetic energy, 1 J = 1 N x (d - 0.0005 m).
  // (The cart starts 2 m out: with 1 m, as before, it went through the spring's ground point.)
  rc::ModelBuilder b("crusher", "SI");
  b.gravity(0.0, 0.0);
  rc::BodySpec cart{"cart", 2.0, 0.1, 2.0, 0.0};
  cart.vx = -1.0;
  cart.car = "train";
  b.body(cart);
  b.element("crush", "crush_spring", {{"ground", 0.0, 0.0}, {"cart", 0.0, 0.0}},
            {{"free_length", 2.0}, {"curve", std::vector<std::vector<double>>{{0.0, 0.0}, {0.001, 1.0}, {2.0, 1.0}}},
             {"unloading_stiffness", 1.0e4}});
  rc::RunSettings s;
  s.t_end = 2.5;
  s.output_interval = 1e-4;
  b.simulation(s);
  CHECK_THAT(b.yaml(), Catch::Contains("car: \"train\""));
  rc::RunSettings settings;
  settings.rtol = 1e-8;
  const rc::Results r = rc::run(b.build(), settings);
  REQUIRE(r.ok());
  REQUIRE(r.summary.cars.size() == 1);
  CHECK(r.summary.cars[0].car == "train");
  CHECK(r.summary.cars[0].max_crush == Approx(1.0005).epsilon(1e-3));
}

TEST_CASE("api: a built model with loads, tables and flags", "[api]") {
  // A constant force F on a critically damped spring-mass settles at F / k; a table force
  // that is zero after 0.1 s returns it to the free length.
  rc::ModelBuilder b("loads", "SI");
  b.gravity(0.0, 0.0);
  b.body({"cart", 2.0, 0.1, 1.0, 0.0});
  b.element("spring", "linear_spring", {{"ground", 0, 0}, {"cart", 0, 0}}, {{"stiffness", 800.0}, {"free_length", 1.0}});
  b.element("damper", "linear_dashpot", {{"ground", 0, 0}, {"cart", 0, 0}}, {{"damping", 80.0}});
  b.force({"cart", 0.0, 0.0}, 40.0, 0.0);
  b.moment("cart", 0.0);
  rc::RunSettings s;
  s.t_end = 2.0;
  b.simulation(s);
  const rc::Results settled = rc::run(b.build());
  CHECK(settled.series("cart.x").back() == Approx(1.05).epsilon(1e-7));

  rc::ModelBuilder pulse("pulse", "SI");
  pulse.gravity(0.0, 0.0);
  pulse.body({"cart", 2.0, 0.1, 1.0, 0.0});
  pulse.element("spring", "linear_spring", {{"ground", 0, 0}, {"cart", 0, 0}}, {{"stiffness", 800.0}, {"free_length", 1.0}});
  pulse.element("damper", "linear_dashpot", {{"ground", 0, 0}, {"cart", 0, 0}}, {{"damping", 80.0}});
  pulse.force({"cart", 0.0, 0.0}, std::vector<std::array<double, 3>>{{0.0, 40.0, 0.0}, {0.1, 40.0, 0.0}, {0.1000001, 0.0, 0.0}});
  pulse.simulation(s);
  const rc::Results back = rc::run(pulse.build());
  const std::vector<double>& x = back.series("cart.x");
  CHECK(*std::max_element(x.begin(), x.end()) > 1.01);
  CHECK(x.back() == Approx(1.0).margin(1e-7));
}

TEST_CASE("api: CFC 60 peaks are taken before the filter's end zone, a larger value there is given apart", "[api][cfc]") {
  // A free 1 kg body pushed by a table force: a 100 ms half-sine of 100 N from t = 0.1 s (all
  // its energy below 10 Hz: it passes CFC 60 within 0.5 %), then, over the run's last 1 ms, a
  // ramp to 1000 N (as a light body ringing at the last row). The filter's extension of the
  // record passes the last sample through whole, so the peak over the whole record would be the
  // 1000 m/s^2 end; before the end zone it is the pulse's 100.
  std::vector<std::array<double, 3>> table;
  for (int k = 0; k <= 100; ++k) table.push_back({0.1 + 1e-3 * k, 100.0 * std::sin(M_PI * k / 100.0), 0.0});
  table.push_back({0.399, 0.0, 0.0});
  table.push_back({0.4, 1000.0, 0.0});
  const rc::Results r = pushed_cart(table, 0.4, 1e-8);
  REQUIRE(r.ok());
  const YAML::Node summary = YAML::Load(r.summary_json)["peak_accelerations"];
  const double g = summary["standard_gravity"].as<double>();
  CHECK(summary["filter"]["end_zone"].as<double>() == Approx(8.3155e-3).epsilon(1e-4));
  const YAML::Node cart = summary["bodies"]["cart"];
  CHECK(cart["magnitude_cfc"]["abs_max"].as<double>() == Approx(100.0).epsilon(5e-3));
  CHECK(cart["magnitude_cfc"]["t"].as<double>() == Approx(0.15).margin(2e-3));
  CHECK(cart["magnitude_cfc"]["g"].as<double>() == Approx(100.0 / g).epsilon(5e-3));
  REQUIRE(cart["magnitude_cfc_end_zone"]);
  CHECK(cart["magnitude_cfc_end_zone"]["abs_max"].as<double>() == Approx(1000.0).epsilon(1e-6));
  CHECK(cart["magnitude_cfc_end_zone"]["t"].as<double>() == Approx(0.4).margin(1e-12));
  // Unfiltered, the end is the peak: those are the samples themselves.
  CHECK(cart["magnitude"]["max"].as<double>() == Approx(1000.0).epsilon(1e-6));

  // Without the end ramp there is nothing larger at the end to give apart.
  table.resize(table.size() - 2);
  const rc::Results p = pushed_cart(table, 0.4, 1e-8);
  const YAML::Node quiet = YAML::Load(p.summary_json)["peak_accelerations"]["bodies"]["cart"];
  CHECK(quiet["magnitude_cfc"]["abs_max"].as<double>() == Approx(cart["magnitude_cfc"]["abs_max"].as<double>()).epsilon(1e-6));
  CHECK_FALSE(quiet["magnitude_cfc_end_zone"]);
  CHECK_FALSE(quiet["magnitude_cfc_interval_mean"]);  // a pulse the rows resolve: the two peaks agree
}

TEST_CASE("api: a CFC 60 peak that aliases at the output rows is named, with the interval means' peak beside it", "[api][cfc]") {
  // A free 1 kg body: the same 100 N half-sine from t = 0.05 s, plus 500 N at 990 Hz all along
  // (a light body ringing). Sampled every 1 ms, 990 Hz folds to 10 Hz, which CFC 60 passes: the
  // rows' peak is about 100 + 500. Averaged over each 1 ms interval, the ringing keeps
  // sin(0.99 pi) / (0.99 pi) = 1.0 % of its amplitude, 5 N: the interval means' peak is the
  // pulse's 100 within 6 %.
  std::vector<std::array<double, 3>> table;
  const double t_end = 0.3, dt = 1.0 / (990.0 * 24.0);  // 24 table rows per period of the ringing
  for (double t = 0.0; t <= t_end + dt; t += dt) {
    const double pulse = t > 0.05 && t < 0.15 ? 100.0 * std::sin(M_PI * (t - 0.05) / 0.1) : 0.0;
    table.push_back({t, pulse + 500.0 * std::sin(2.0 * M_PI * 990.0 * t), 0.0});
  }
  const rc::Results r = pushed_cart(table, t_end, 1e-6);
  REQUIRE(r.ok());
  const YAML::Node cart = YAML::Load(r.summary_json)["peak_accelerations"]["bodies"]["cart"];
  INFO(r.summary_json.substr(r.summary_json.find("\"cart\"")));
  CHECK(cart["magnitude_cfc"]["abs_max"].as<double>() > 400.0);
  REQUIRE(cart["magnitude_cfc_interval_mean"]);
  CHECK(cart["magnitude_cfc_interval_mean"]["abs_max"].as<double>() == Approx(100.0).epsilon(0.06));
  CHECK(cart["magnitude_cfc_interval_mean"]["t"].as<double>() == Approx(0.1).margin(0.01));
}

TEST_CASE("api: errors name the file and line, the element or the key", "[api]") {
  CHECK_THROWS_WITH(rc::Model::load("/no/such/model.yaml"), Catch::Contains("cannot open the model file"));
  CHECK_THROWS_WITH(rc::Model::load(kTwoCar, {"elements.anticlimbr.horizontal_yield_deflection*=1.2"}),
                    Catch::Contains("no number at 'elements.anticlimbr.horizontal_yield_deflection'"));
  CHECK_THROWS_WITH(rc::Model::from_yaml("railcrash: 1\nname: x\nunits: SI\nbodies: []\n", "inline.yaml"),
                    Catch::Contains("inline.yaml:4:"));
  // A dangling body name in a built model: the element and the body, no meaningless line.
  rc::ModelBuilder b("dangling", "SI");
  b.body({"cart", 1.0, 0.1, 1.0, 0.0});
  b.element("spring", "linear_spring", {{"ground", 0, 0}, {"crat", 0, 0}}, {{"stiffness", 10.0}});
  CHECK_THROWS_WITH(b.build(), Catch::StartsWith("element 'spring' (linear_spring): point 2: unknown body 'crat' (did you mean 'cart'?)"));
  // Non-finite numbers are not numbers.
  rc::ModelBuilder nan("nan", "SI");
  nan.body({"cart", std::nan(""), 0.1, 1.0, 0.0});
  CHECK_THROWS_AS(nan.build(), railcrash::InputError);
  rc::ModelBuilder wrong_kind("kind", "SI");
  wrong_kind.body({"cart", 1.0, 0.1, 1.0, 0.0});
  wrong_kind.element("spring", "linear_spring", {{"ground", 0, 0}, {"cart", 0, 0}}, {{"stiffness", std::vector<double>{1.0, 2.0}}});
  CHECK_THROWS_WITH(wrong_kind.build(), Catch::Contains("stiffness"));
  // Run settings.
  const rc::Model model = oscillator(2.0, 800.0).build();
  rc::RunSettings bad;
  bad.integrator = "rk4";
  // Refused by the loader's one integrator check, named as the API field that gave it.
  CHECK_THROWS_WITH(rc::run(model, bad),
                    Catch::StartsWith("RunSettings.integrator = rk4: simulation: integrator must be auto, ida or euler, not 'rk4'"));
  bad = {};
  bad.rtol = -1.0;
  CHECK_THROWS_WITH(rc::run(model, bad), Catch::StartsWith("RunSettings.rtol = -1: simulation: rtol must be a positive number"));
  bad = {};
  bad.t_end = 0.01;
  const rc::Results r = rc::run(model, bad);
  CHECK_THROWS_WITH(r.series("cart.xx"), Catch::Contains("did you mean 'cart.x'"));
}

TEST_CASE("api: a stop flag ends the run early, reported, not thrown", "[api]") {
  const rc::Model model = oscillator(2.0, 800.0).build();
  const std::atomic<bool> stop{true};
  const rc::Results r = rc::run(model, {}, &stop);
  CHECK_FALSE(r.ok());
  CHECK_FALSE(r.summary.message.empty());
  CHECK(r.summary.t_reached < 1.0);
}

TEST_CASE("api: one model run from several threads at once gives the runs done alone", "[api]") {
  const rc::Model model = rc::Model::load(kTwoCar, {"simulation.t_end=0.03"});
  rc::RunSettings settings;
  settings.rtol = 1e-4;
  const rc::Results alone = rc::run(model, settings);
  std::vector<rc::Results> together(3);
  std::vector<std::thread> threads;
  for (auto& slot : together) threads.emplace_back([&, out = &slot] { *out = rc::run(model, settings); });
  for (auto& t : threads) t.join();
  for (const rc::Results& r : together) {
    REQUIRE(r.ok());
    CHECK(r.values == alone.values);
    CHECK(r.events.size() == alone.events.size());
  }
}

namespace {

/// Two 40 t cars of a multiple unit joined by a draft gear (spring 10 kN/mm, damper 50 N s/mm),
/// the first at 5 m/s, in the crash codes' mm-t-s-N: its lengths are mm, converted to SI when read.
const std::string kDraftGearMm = R"(railcrash: 1
name: two 40 t cars on a draft gear
units: mm-t-s-N
gravity: [0, 0]
bodies:
  - {name: car1, mass: 40, inertia: 2.0e9, position: [0, 0], velocity: [5000, 0], car: car1}
  - {name: car2, mass: 40, inertia: 2.0e9, position: [25000, 0], car: car2}
elements:
  - {name: car1_rail, type: slider_joint, axis: [1, 0], points: [{body: ground}, {body: car1}]}
  - {name: car2_rail, type: slider_joint, axis: [1, 0], points: [{body: ground, at: [25000, 0]}, {body: car2}]}
  - {name: draft_gear, type: linear_spring, stiffness: 1.0e4, free_length: 25000, points: [{body: car1}, {body: car2}]}
  - {name: draft_gear_damper, type: linear_dashpot, damping: 50, points: [{body: car1}, {body: car2}]}
simulation:
  t_end: 0.2
  integrator: ida
  rtol: 1.0e-3
  output_interval: 0.002
)";

}  // namespace

TEST_CASE("api: atol is in the model file's length unit, as simulation.atol and --atol are", "[api]") {
  // atol 0.01 mm of an mm-t-s-N model: given as RunSettings, in the file and as --atol.
  rc::RunSettings api_atol;
  api_atol.atol = 0.01;
  const rc::Results from_api = rc::run(rc::Model::from_yaml(kDraftGearMm, "draft_gear.yaml"), api_atol);
  REQUIRE(from_api.ok());
  const std::string with_file_atol = kDraftGearMm + "  atol: 0.01\n";
  const rc::Results from_file = rc::run(rc::Model::from_yaml(with_file_atol, "draft_gear.yaml"));
  REQUIRE(from_file.ok());
  railcrash::RunOverrides command_line;
  command_line.atol = 0.01;
  const railcrash::LoadedModel with_option =
      railcrash::load_model_text(kDraftGearMm, "draft_gear.yaml", {}, railcrash::option_settings(command_line));
  const railcrash::RunReport from_option =
      railcrash::run_model(with_option.model, with_option.run_spec, "", nullptr, false, /*keep_in_memory=*/true);
  REQUIRE(from_option.outcome.ok);
  CHECK(from_api.columns == from_file.columns);
  CHECK(from_api.values == from_file.values);  // the same doubles, every sample
  CHECK(from_api.values == from_option.series);
  CHECK(from_api.summary.steps == from_file.summary.steps);
  // The tolerance matters on this run: read as metres (1000 times looser) the run differs.
  rc::RunSettings metres;
  metres.atol = 10.0;  // [mm] = 0.01 m
  const rc::Results looser = rc::run(rc::Model::from_yaml(kDraftGearMm, "draft_gear.yaml"), metres);
  REQUIRE(looser.ok());
  CHECK(looser.values != from_api.values);
}

TEST_CASE("api: a run's settings are listed in its provenance and named by their field in messages", "[api]") {
  const rc::Model model = rc::Model::from_yaml(kDraftGearMm, "draft_gear.yaml", {"simulation.t_end=0.05"});
  rc::RunSettings settings;
  settings.rtol = 1e-4;
  settings.atol = 0.01;
  const rc::Results r = rc::run(model, settings);
  REQUIRE(r.ok());
  CHECK_THAT(r.summary_json,
             Catch::Contains("\"settings\": [\"simulation.t_end=0.05\", \"simulation.rtol=0.0001\", \"simulation.atol=0.01\"]"));
  rc::RunSettings bad;
  bad.atol = -1.0;
  CHECK_THROWS_WITH(rc::run(model, bad), "draft_gear.yaml: RunSettings.atol = -1: simulation: atol must be positive");
}
