// Model files: what a valid file gives, and that every bad input is an InputError whose
// message names the file and line, the body / element / key at fault and what to change.
#include <catch2/catch.hpp>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "railcrash/elements/crush.hpp"
#include "railcrash/elements/joints.hpp"
#include "railcrash/elements/springs.hpp"
#include "railcrash/model/model_io.hpp"
#include "railcrash/results/run.hpp"
#include "railcrash/solver/dae_system.hpp"
#include "railcrash/solver/initial_conditions.hpp"
#include "support.hpp"

using namespace railcrash;
using Catch::Matchers::Contains;
using Catch::Matchers::StartsWith;

namespace {

// The valid SI model the bad inputs are made from, in sections so one can be left out.
const std::string kHeader = R"(railcrash: 1
name: io test model
units: SI
)";
const std::string kBodies = R"(bodies:
  - name: bob
    mass: 1.0
    inertia: 0.5
    position: [1.0, 2.0]
  - name: cart
    mass: 3.0
    inertia: 0.25
    position: [3.0, 0.0]
    angle: 0.1
    velocity: [1.5, -0.5]
    angular_velocity: 0.2
)";
const std::string kElements = R"(elements:
  - name: spring
    type: linear_spring
    stiffness: 100.0
    free_length: 1.5
    points: [{body: bob, at: [0, 0]}, {body: cart, at: [0.5, 0]}]
  - name: damper
    type: linear_dashpot
    damping: 4.0
    points:
      - {body: ground, at: [0, 2]}
      - {body: bob}
  - name: slide
    type: slider_joint
    axis: [1, 0]
    points: [{body: ground, at: [0, 0]}, {body: cart, at: [0, 0]}]
)";
const std::string kLoads = R"(loads:
  - {type: force, body: bob, at: [0.1, 0.0], value: [1.0, -2.0]}
  - type: moment
    body: cart
    value:
      - [0.0, 0.0]
      - [1.0, 10.0]
      - [3.0, -10.0]
)";
const std::string kSimulation = R"(simulation:
  integrator: euler
  t_end: 2.0
  dt: 1.0e-4
  output_interval: 0.01
)";
const std::string kBase = kHeader + kBodies + kElements + kLoads + kSimulation;

/// `text` with the single occurrence of `from` replaced by `to`.
std::string edit(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  INFO("edit: '" << from << "'");
  REQUIRE(at != std::string::npos);
  REQUIRE(text.find(from, at + 1) == std::string::npos);
  text.replace(at, from.size(), to);
  return text;
}

/// 1-based line of the single occurrence of `marker` in `text`.
int line_of(const std::string& text, const std::string& marker) {
  const auto at = text.find(marker);
  INFO("marker: '" << marker << "'");
  REQUIRE(at != std::string::npos);
  REQUIRE(text.find(marker, at + 1) == std::string::npos);
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
}

/// The InputError message loading `text` gives ("" and a failed check when there is none).
std::string load_error(const std::string& text, const std::vector<std::string>& overrides = {}) {
  try {
    (void)load_model_text(text, "test.yaml", overrides);
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    FAIL_CHECK("not an InputError: " << e.what());
    return "";
  }
  FAIL_CHECK("the model was accepted");
  return "";
}

/// Loading `text` fails with a message starting "test.yaml:LINE: " and containing every part.
void expect_error(const std::string& what, const std::string& text, int line, const std::vector<std::string>& parts,
                  const std::vector<std::string>& overrides = {}) {
  INFO("case: " << what);
  const std::string message = load_error(text, overrides);
  INFO("message: " << message);
  CHECK_THAT(message, StartsWith("test.yaml:" + std::to_string(line) + ": "));
  for (const auto& part : parts) CHECK_THAT(message, Contains(part));
}

/// Loads `text` and runs the initial assembly; returns the InputError message ("" if none).
std::string assembly_error(const std::string& text) {
  const Model model = testing::model_from_text(text);
  DaeSystem system(model);
  std::vector<double> y = system.initial_state();
  try {
    (void)assemble_initial_state(system, y);
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    FAIL_CHECK("not an InputError: " << e.what());
    return "";
  }
  FAIL_CHECK("the joints were accepted");
  return "";
}

std::string single_body_model(const std::string& body, const std::string& elements) {
  return "railcrash: 1\nname: constraints\nunits: SI\nbodies:\n" + body + "elements:\n" + elements +
         "simulation:\n  t_end: 1.0\n";
}

}  // namespace

// ---------------------------------------------------------------------------------------
// 1. Valid models
// ---------------------------------------------------------------------------------------

TEST_CASE("a valid SI model loads with its bodies, elements, loads and settings", "[model_io]") {
  const LoadedModel loaded = testing::loaded_from_text(kBase);
  const Model& model = loaded.model;
  CHECK(model.finalized());
  CHECK(model.name == "io test model");
  CHECK(model.file == "test.yaml");
  CHECK(model.units == UnitSystem::SI);
  CHECK(model.gravity_x == 0.0);
  CHECK(model.gravity_y == Approx(-9.80665).epsilon(1e-15));

  REQUIRE(model.body_count() == 2);
  const Body& bob = model.bodies()[0];
  const Body& cart = model.bodies()[1];
  CHECK(bob.name == "bob");
  CHECK(bob.mass == 1.0);
  CHECK(bob.inertia == 0.5);
  CHECK(bob.x == 1.0);
  CHECK(bob.y == 2.0);
  CHECK(bob.angle == 0.0);
  CHECK(bob.vx == 0.0);
  CHECK(bob.where.line == line_of(kBase, "- name: bob"));
  CHECK(cart.name == "cart");
  CHECK(cart.mass == 3.0);
  CHECK(cart.inertia == 0.25);
  CHECK(cart.x == 3.0);
  CHECK(cart.y == 0.0);
  CHECK(cart.angle == 0.1);
  CHECK(cart.vx == 1.5);
  CHECK(cart.vy == -0.5);
  CHECK(cart.angular_velocity == 0.2);
  CHECK(model.find_body("cart") == 1);
  CHECK(model.find_body("ground") == kGround);
  CHECK_FALSE(model.find_body("nobody").has_value());

  REQUIRE(model.elements().size() == 3);
  const auto& spring_element = *model.elements()[0];
  CHECK(spring_element.name() == "spring");
  CHECK(spring_element.type() == "linear_spring");
  CHECK(spring_element.where().line == line_of(kBase, "- name: spring"));
  const auto* spring = dynamic_cast<const LinearSpring*>(&spring_element);
  REQUIRE(spring != nullptr);
  CHECK(spring->stiffness == 100.0);
  REQUIRE(spring->free_length.has_value());
  CHECK(*spring->free_length == 1.5);
  CHECK(spring->point(1).body == 1);
  CHECK(spring->point(1).sx == 0.5);
  const auto* damper = dynamic_cast<const LinearDashpot*>(model.elements()[1].get());
  REQUIRE(damper != nullptr);
  CHECK(damper->damping == 4.0);
  CHECK(damper->point(0).body == kGround);
  CHECK(damper->point(0).sy == 2.0);
  CHECK(damper->point(1).sx == 0.0);  // 'at' left out: the centre of mass
  const auto* slide = dynamic_cast<const SliderJoint*>(model.elements()[2].get());
  REQUIRE(slide != nullptr);
  CHECK(slide->axis_x == 1.0);
  CHECK(slide->axis_y == 0.0);
  CHECK(model.constraint_rows() == 2);
  CHECK(model.degrees_of_freedom() == 4);

  REQUIRE(model.loads().size() == 2);
  const Load& force = model.loads()[0];
  CHECK(force.kind == Load::Kind::Force);
  CHECK(force.body == 0);
  CHECK(force.sx == 0.1);
  CHECK(force.sy == 0.0);
  CHECK(force.value.times == std::vector<double>{0.0});
  for (double t : {-1.0, 0.0, 0.7, 100.0}) {
    CHECK(force.value.at(t)[0] == 1.0);
    CHECK(force.value.at(t)[1] == -2.0);
  }
  const Load& moment = model.loads()[1];
  CHECK(moment.kind == Load::Kind::Moment);
  CHECK(moment.body == 1);
  CHECK(moment.value.times == std::vector<double>{0.0, 1.0, 3.0});
  CHECK(moment.value.at(0.0)[0] == 0.0);
  CHECK(moment.value.at(0.25)[0] == Approx(2.5));   // linear between rows
  CHECK(moment.value.at(1.0)[0] == Approx(10.0));
  CHECK(moment.value.at(1.5)[0] == Approx(5.0));
  CHECK(moment.value.at(2.0)[0] == Approx(0.0).margin(1e-12));
  CHECK(moment.value.at(2.5)[0] == Approx(-5.0));
  CHECK(moment.value.at(-3.0)[0] == 0.0);           // held before the first row
  CHECK(moment.value.at(3.0)[0] == -10.0);
  CHECK(moment.value.at(50.0)[0] == -10.0);         // held after the last row
  CHECK(moment.value.at(1.5)[1] == 0.0);

  CHECK(loaded.run_spec.simulation.t_end == 2.0);
  CHECK(loaded.run_spec.simulation.integrator == IntegratorKind::Euler);
  CHECK(loaded.run_spec.simulation.dt == 1.0e-4);
  CHECK(loaded.run_spec.simulation.output_interval == 0.01);
  CHECK(loaded.run_spec.simulation.rtol == 1e-6);  // default
  CHECK_FALSE(loaded.run_spec.simulation.atol.has_value());
  CHECK_FALSE(loaded.run_spec.simulation.force_dt);
}

TEST_CASE("a tabulated force takes [t, Fx, Fy] and [t, [Fx, Fy]] rows", "[model_io]") {
  const std::string text = edit(kBase, "value: [1.0, -2.0]}", "value: [[0.0, 0.0, 0.0], [2.0, [4.0, -8.0]]]}");
  const Model model = testing::model_from_text(text);
  const TimeTable& table = model.loads()[0].value;
  CHECK(table.times == std::vector<double>{0.0, 2.0});
  CHECK(table.at(0.5)[0] == Approx(1.0));
  CHECK(table.at(0.5)[1] == Approx(-2.0));
  CHECK(table.at(9.0)[0] == 4.0);
  CHECK(table.at(9.0)[1] == -8.0);
}

TEST_CASE("the verification slider-crank file loads", "[model_io]") {
  const LoadedModel loaded = load_model(std::string(RAILCRASH_SOURCE_DIR) + "/verification/cases/slider_crank.yaml");
  const Model& model = loaded.model;
  CHECK(model.name == "SUNDIALS GGL slider-crank (idasSlCrank_dns)");
  CHECK(model.gravity_x == 0.0);
  CHECK(model.gravity_y == 0.0);
  REQUIRE(model.body_count() == 2);
  CHECK(model.bodies()[1].name == "rod");
  CHECK(model.bodies()[1].inertia == 2.0);
  CHECK(model.bodies()[1].x == Approx(0.8660254037844386));
  CHECK(model.bodies()[1].angle == Approx(-0.5235987755982989));
  CHECK(model.elements().size() == 5);
  CHECK(model.constraint_rows() == 5);  // pin 2 + pin 2 + sliding pin 1
  CHECK(model.loads().size() == 1);
  CHECK(loaded.run_spec.simulation.t_end == 10.0);
  CHECK(loaded.run_spec.simulation.integrator == IntegratorKind::Ida);
  REQUIRE(loaded.run_spec.simulation.atol.has_value());
  CHECK(*loaded.run_spec.simulation.atol == 1.0e-7);
  CHECK(loaded.run_spec.simulation.output_interval == 0.4);
}

TEST_CASE("a missing model file is an InputError naming the path", "[model_io]") {
  const std::string path = std::string(RAILCRASH_SOURCE_DIR) + "/tests/no_such_model.yaml";
  CHECK_THROWS_AS(load_model(path), InputError);
  CHECK_THROWS_WITH(load_model(path), Contains(path) && Contains("cannot open"));
}

TEST_CASE("in-lbf-s models take weight in lbf and default to 386.088 in/s^2", "[model_io]") {
  const std::string text = R"(railcrash: 1
name: imperial
units: in-lbf-s
bodies:
  - name: car
    weight: 772.176
    inertia: 10.0
    position: [0.0, 20.0]
  - name: block
    mass: 0.5
    inertia: 0.0
    position: [100.0, 20.0]
simulation:
  t_end: 0.1
)";
  const Model model = testing::model_from_text(text);
  CHECK(model.units == UnitSystem::InLbfS);
  CHECK(model.gravity_x == 0.0);
  CHECK(model.gravity_y == Approx(-386.088).epsilon(1e-15));
  CHECK(standard_gravity(UnitSystem::InLbfS) == 386.088);
  CHECK(model.bodies()[0].mass == Approx(772.176 / 386.088).epsilon(1e-15));
  CHECK(model.bodies()[0].mass == Approx(2.0).epsilon(1e-12));
  CHECK(model.bodies()[1].mass == 0.5);  // mass is still accepted directly
  CHECK(model.bodies()[1].inertia == 0.0);

  const Model light = testing::model_from_text(edit(text, "weight: 772.176", "weight: 1000"));
  CHECK(light.bodies()[0].mass == Approx(1000.0 / 386.088).epsilon(1e-15));

  const Model custom = testing::model_from_text(edit(text, "units: in-lbf-s\n", "units: in-lbf-s\ngravity: [0, -32.2]\n"));
  CHECK(custom.gravity_y == -32.2);
  CHECK(custom.bodies()[0].mass == Approx(2.0).epsilon(1e-12));  // weight still means standard gravity
}

TEST_CASE("gravity: SI default, [0, 0] switches it off, any vector is taken as given", "[model_io]") {
  CHECK(testing::model_from_text(kBase).gravity_y == Approx(-9.80665).epsilon(1e-15));
  CHECK(standard_gravity(UnitSystem::SI) == 9.80665);
  const Model off = testing::model_from_text(edit(kBase, "units: SI\n", "units: SI\ngravity: [0, 0]\n"));
  CHECK(off.gravity_x == 0.0);
  CHECK(off.gravity_y == 0.0);
  const Model tilted = testing::model_from_text(edit(kBase, "units: SI\n", "units: SI\ngravity: [1.5, -3.0]\n"));
  CHECK(tilted.gravity_x == 1.5);
  CHECK(tilted.gravity_y == -3.0);
}

TEST_CASE("overrides given with --set change the model before it is checked", "[model_io]") {
  const LoadedModel loaded = load_model_text(kBase, "test.yaml", {"simulation.t_end=0.5", "bodies.bob.mass=2", "elements.spring.stiffness=200"});
  const Model& model = loaded.model;
  CHECK(loaded.run_spec.simulation.t_end == 0.5);
  CHECK(model.bodies()[0].mass == 2.0);
  CHECK(model.bodies()[1].mass == 3.0);  // untouched
  const auto* spring = dynamic_cast<const LinearSpring*>(model.elements()[0].get());
  REQUIRE(spring != nullptr);
  CHECK(spring->stiffness == 200.0);
  CHECK(*spring->free_length == 1.5);
  CHECK(loaded.run_spec.simulation.dt == 1.0e-4);  // the rest of the section stays

  const LoadedModel more_loaded = load_model_text(kBase, "test.yaml", {"gravity=[0, 0]", "simulation.integrator=ida", "simulation.rtol=1e-8",
                                                          "bodies.cart.position=[5, 0]", "elements.slide.axis=[0, 1]"});
  const Model& more = more_loaded.model;
  CHECK(more.gravity_y == 0.0);
  CHECK(more_loaded.run_spec.simulation.integrator == IntegratorKind::Ida);
  CHECK(more_loaded.run_spec.simulation.rtol == 1e-8);
  CHECK(more.bodies()[1].x == 5.0);
  const auto* slide = dynamic_cast<const SliderJoint*>(more.elements()[2].get());
  REQUIRE(slide != nullptr);
  CHECK(slide->axis_x == 0.0);
  CHECK(slide->axis_y == 1.0);

  // A simulation section may come entirely from the command line.
  const LoadedModel no_section_loaded = load_model_text(kHeader + kBodies, "test.yaml", {"simulation.t_end=3"});
  CHECK(no_section_loaded.run_spec.simulation.t_end == 3.0);
}

TEST_CASE("the run command's options go through --set's path, after it, and are named in messages", "[model_io]") {
  const auto path = testing::temp_path("railcrash_test_options.yaml");
  std::ofstream(path) << kBase;
  RunOverrides options;
  options.t_end = 0.25;
  options.integrator = IntegratorKind::Ida;
  options.max_steps = 500;
  options.force_dt = true;
  const std::vector<OptionSetting> settings = option_settings(options);
  CHECK(settings.size() == 4);
  // Applied after --set: the option wins over a --set of the same key.
  const LoadedModel loaded = load_model(path.string(), {"simulation.t_end=9"}, settings);
  CHECK(loaded.run_spec.simulation.t_end == 0.25);
  CHECK(loaded.run_spec.simulation.integrator == IntegratorKind::Ida);
  CHECK(loaded.run_spec.simulation.max_steps == 500);
  CHECK(loaded.run_spec.simulation.force_dt);
  // A bad value is reported with the option as the user wrote it, not a file line.
  RunOverrides bad;
  bad.t_end = -1.5;
  CHECK_THROWS_WITH(load_model(path.string(), {}, option_settings(bad)),
                    Contains("railcrash_test_options.yaml: --t-end -1.5: simulation: t_end must be positive"));
  bad = RunOverrides{};
  bad.max_steps = 0;
  CHECK_THROWS_WITH(load_model(path.string(), {}, option_settings(bad)),
                    Contains("--max-steps 0: simulation: max_steps must be a whole number of at least 1"));
  // Only t_end changed: the row bound names --t-end, though the interval is the file's.
  bad = RunOverrides{};
  bad.t_end = 1e300;
  CHECK_THROWS_WITH(load_model(path.string(), {}, option_settings(bad)), Contains("--t-end 1e+300: simulation: output_interval"));
  std::filesystem::remove(path);
}

TEST_CASE("simulation: max_steps in a model file bounds the steps and must be a whole number of at least 1", "[model_io]") {
  CHECK(load_model_text(edit(kBase, "simulation:\n", "simulation:\n  max_steps: 1234\n"), "test.yaml").run_spec.simulation.max_steps == 1234);
  const std::string fractional = edit(kBase, "simulation:\n", "simulation:\n  max_steps: 2.5\n");
  CHECK_THAT(load_error(fractional),
             Contains("test.yaml:" + std::to_string(line_of(fractional, "max_steps: 2.5")) + ": simulation: max_steps must be a whole number"));
}

TEST_CASE("bad --set overrides are InputErrors naming the setting", "[model_io]") {
  const auto error = [](const std::vector<std::string>& overrides) {
    try {
      (void)load_model_text(kBase, "test.yaml", overrides);
    } catch (const InputError& e) {
      return std::string(e.what());
    } catch (const std::exception& e) {
      FAIL_CHECK("not an InputError: " << e.what());
      return std::string();
    }
    FAIL_CHECK("the override was accepted");
    return std::string();
  };
  std::string m = error({"bodies.nobody.mass=2"});
  CHECK_THAT(m, Contains("bodies.nobody.mass=2") && Contains("no body named 'nobody'"));
  m = error({"elements.nothing.stiffness=200"});
  CHECK_THAT(m, Contains("no element named 'nothing'"));
  m = error({"simulation.t_end"});
  CHECK_THAT(m, Contains("KEY=VALUE"));
  m = error({"simulation.t_end=[0.5"});
  CHECK_THAT(m, Contains("not valid YAML"));
  // A bad value is reported against the setting, not against a line of the file.
  m = error({"simulation.t_end=-1"});
  CHECK_THAT(m, StartsWith("test.yaml: --set 'simulation.t_end=-1': ") && Contains("t_end must be positive"));
  m = error({"bodies.bob.mass=heavy"});
  CHECK_THAT(m, StartsWith("test.yaml: --set 'bodies.bob.mass=heavy': ") && Contains("body 'bob': mass must be a number"));
  m = error({"gravity=[0, down]"});
  CHECK_THAT(m, Contains("--set 'gravity=[0, down]'") && Contains("gravity entry 2 must be a number"));
  m = error({"elements.spring.stifness=200"});
  CHECK_THAT(m, StartsWith("test.yaml: --set 'elements.spring.stifness=200': ") && Contains("unknown key 'stifness'") &&
                    Contains("did you mean 'stiffness'"));
  m = error({"simulation.tend=1"});
  CHECK_THAT(m, StartsWith("test.yaml: --set 'simulation.tend=1': ") && Contains("did you mean 't_end'"));
  m = error({"bodies.mass=2"});
  CHECK_THAT(m, Contains("bodies.<name>.<key>"));
  m = error({"gravity.x=1"});
  CHECK_THAT(m, Contains("'gravity' is not a section"));
  m = error({"simulation.force_dt=maybe"});
  CHECK_THAT(m, Contains("force_dt must be true or false"));
  m = error({"a.b.c.d=1"});
  CHECK_THAT(m, Contains("KEY must be"));
}

namespace {

/// Writes `text` to a file in a fresh temporary folder; returns its path.
std::string write_file(const std::string& folder, const std::string& name, const std::string& text) {
  const auto dir = testing::temp_path("railcrash_test_variants_" + folder);
  std::filesystem::create_directories(dir);
  std::ofstream(dir / name) << text;
  return (dir / name).string();
}

}  // namespace

TEST_CASE("a model variant is its base model with the keys it sets changed", "[model_io]") {
  write_file("ok", "base.yaml", kBase);
  const std::string variant = write_file("ok", "variant.yaml",
                                         "railcrash: 1\nvariant_of: base.yaml\nname: stiffer\n"
                                         "set:\n  elements.spring.stiffness: 250   # why\n  gravity: [0, 0]\n"
                                         "  bodies.bob.mass*: 3\n");
  const LoadedModel loaded = load_model(variant, {"simulation.t_end=0.25"});
  const Model& model = loaded.model;
  CHECK(model.name == "stiffer");
  const auto* spring = dynamic_cast<const LinearSpring*>(model.elements()[0].get());
  REQUIRE(spring != nullptr);
  CHECK(spring->stiffness == 250.0);
  CHECK(model.gravity_y == 0.0);
  CHECK(model.bodies()[0].mass == Approx(3.0));   // 1 x 3
  CHECK(model.bodies()[1].mass == 3.0);            // the base's
  CHECK(loaded.run_spec.simulation.t_end == 0.25);           // --set still applies, after the variant
  const Model base = load_model(write_file("ok", "base.yaml", kBase)).model;
  CHECK(base.elements().size() == model.elements().size());
}

TEST_CASE("model variant errors name the variant's line or the base file", "[model_io]") {
  write_file("bad", "base.yaml", kBase);
  const auto error = [](const std::string& path) {
    try {
      (void)load_model(path);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("(loaded)");
  };
  const std::string missing_key = write_file("bad", "v1.yaml", "railcrash: 1\nvariant_of: base.yaml\nset:\n  elements.nothing.stiffness: 2\n");
  CHECK_THAT(error(missing_key), StartsWith(missing_key + ":4: set 'elements.nothing.stiffness'") && Contains("no element named 'nothing'"));
  const std::string bad_value = write_file("bad", "v2.yaml", "railcrash: 1\nvariant_of: base.yaml\nset:\n  simulation.t_end: -1\n");
  CHECK_THAT(error(bad_value), StartsWith(bad_value + ":4: set 'simulation.t_end'") && Contains("t_end must be positive"));
  const std::string no_base = write_file("bad", "v3.yaml", "railcrash: 1\nvariant_of: nowhere.yaml\n");
  CHECK_THAT(error(no_base), StartsWith(no_base + ":2: ") && Contains("cannot open the base model"));
  const std::string other_key = write_file("bad", "v4.yaml", "railcrash: 1\nvariant_of: base.yaml\nbodies: []\n");
  CHECK_THAT(error(other_key), StartsWith(other_key + ":3: ") && Contains("unknown key 'bodies'"));
  const std::string chained = write_file("bad", "v5.yaml", "railcrash: 1\nvariant_of: v1.yaml\n");
  CHECK_THAT(error(chained), StartsWith(chained + ":2: ") && Contains("is itself a variant"));
  const std::string self = write_file("bad", "v6.yaml", "railcrash: 1\nvariant_of: v6.yaml\n");
  CHECK_THAT(error(self), Contains("is itself a variant"));
  const std::string no_value = write_file("bad", "v7.yaml", "railcrash: 1\nvariant_of: base.yaml\nset:\n  simulation.t_end:\n");
  CHECK_THAT(error(no_value), StartsWith(no_value + ":4: ") && Contains("give a value"));
}

TEST_CASE("the report's corrected final model is the printed one with three proposals", "[model_io]") {
  const std::string folder = std::string(RAILCRASH_SOURCE_DIR) + "/models/report/";
  const Model printed = load_model(folder + "final_two_car.yaml").model;
  const Model corrected = load_model(folder + "final_two_car_corrected.yaml").model;
  const auto body = [](const Model& m, const std::string& name) {
    for (const Body& b : m.bodies())
      if (b.name == name) return b;
    FAIL("no body " << name);
    return Body{};
  };
  CHECK(body(printed, "car1_center_body").inertia == 253200.0);  // Table 6 as printed
  CHECK(body(corrected, "car1_center_body").inertia == 2.7e6);   // the proposal T6-1
  const auto spring = [](const Model& m, const std::string& name) {
    for (const auto& e : m.elements())
      if (e->name() == name) return dynamic_cast<const LinearSpring&>(*e).free_length.value();
    FAIL("no element " << name);
    return 0.0;
  };
  for (const char* name : {"car1_front_susp_spring", "car1_rear_susp_spring", "car2_front_susp_spring", "car2_rear_susp_spring"})
    CHECK(spring(printed, name) == 20.04);  // Table 8 as printed, both cars
  CHECK(spring(corrected, "car1_front_susp_spring") == 24.98);
  CHECK(spring(corrected, "car1_rear_susp_spring") == 24.98);
  CHECK(spring(corrected, "car2_front_susp_spring") == 20.04);
}

// ---------------------------------------------------------------------------------------
// 2. Bad input: file, line, culprit and what to change
// ---------------------------------------------------------------------------------------

TEST_CASE("malformed YAML is an InputError at the line at fault", "[model_io]") {
  // An unclosed '[' is noticed by yaml-cpp only on the next line; the message points at the bracket.
  std::string text = edit(kBase, "position: [1.0, 2.0]", "position: [1.0, 2.0");
  expect_error("unclosed [", text, line_of(text, "position: [1.0, 2.0\n"), {"not valid YAML", "'['"});
  text = edit(kBase, "- {type: force, body: bob, at: [0.1, 0.0], value: [1.0, -2.0]}",
              "- {type: force, body: bob, at: [0.1, 0.0], value: [1.0, -2.0]");
  expect_error("unclosed {", text, line_of(text, "- {type: force"), {"not valid YAML", "'{'"});
  text = edit(kBase, "    mass: 3.0\n", "   mass: 3.0\n");
  expect_error("bad indentation", text, line_of(text, "   mass: 3.0"), {"not valid YAML"});
  text = edit(kBase, "    inertia: 0.25\n", "\tinertia: 0.25\n");
  expect_error("tab", text, line_of(text, "\tinertia"), {"not valid YAML", "tab"});
  text = edit(kBase, "    angle: 0.1\n", "    angle: 0.1\n   - stray\n");
  expect_error("stray list item", text, line_of(text, "- stray"), {"not valid YAML"});
  // A '[' inside a comment or a quoted name does not count as the open bracket.
  text = edit(edit(kBase, "name: io test model", "name: 'io [test] model' # [draft"), "velocity: [1.5, -0.5]",
              "velocity: [1.5, -0.5");
  expect_error("unclosed [ after comment", text, line_of(text, "velocity: [1.5"), {"not valid YAML"});
  // ... nor does one in a block scalar.
  text = edit(edit(kBase, "units: SI\n", "units: SI\ndescription: |\n  [draft {\n   see [1\n"), "velocity: [1.5, -0.5]",
              "velocity: [1.5, -0.5");
  expect_error("unclosed [ after block scalar", text, line_of(text, "velocity: [1.5"),
               {"not valid YAML", "never closed", "add the matching ']'"});
}

TEST_CASE("the file must be a map", "[model_io]") {
  expect_error("scalar document", "just words\n", 1, {"must be a YAML map"});
  expect_error("list document", "- a\n- b\n", 1, {"must be a YAML map"});
  CHECK_THROWS_AS(testing::model_from_text(""), InputError);
  CHECK_THROWS_WITH(testing::model_from_text(""), StartsWith("test.yaml: ") && Contains("must be a YAML map"));
  CHECK_THROWS_WITH(load_model_text("just words\n", "test.yaml", {"simulation.t_end=1"}), Contains("must be a YAML map"));
}

TEST_CASE("missing required keys name the key and where it belongs", "[model_io]") {
  expect_error("railcrash", edit(kBase, "railcrash: 1\n", ""), 1, {"missing required key 'railcrash'", "railcrash: 1"});
  expect_error("name", edit(kBase, "name: io test model\n", ""), 1, {"missing required key 'name'"});
  expect_error("units", edit(kBase, "units: SI\n", ""), 1, {"missing required key 'units'"});
  expect_error("bodies", kHeader + kElements + kSimulation, 1, {"missing required key 'bodies'"});
  expect_error("simulation", kHeader + kBodies + kElements + kLoads, 1, {"missing required key 'simulation'", "t_end"});
  std::string text = edit(kBase, "  t_end: 2.0\n", "");
  expect_error("t_end", text, line_of(text, "integrator: euler"), {"simulation: missing required key 't_end'"});

  const int bob = line_of(kBase, "- name: bob");
  expect_error("mass", edit(kBase, "    mass: 1.0\n", ""), bob, {"body 'bob'", "missing required key 'mass'"});
  expect_error("inertia", edit(kBase, "    inertia: 0.5\n", ""), bob, {"body 'bob'", "missing required key 'inertia'"});
  expect_error("position", edit(kBase, "    position: [1.0, 2.0]\n", ""), bob,
               {"body 'bob'", "missing required key 'position'"});
  text = edit(kBase, "  - name: bob\n", "  - mass_first: true\n");
  expect_error("body name", text, line_of(text, "mass_first"), {"body: missing required key 'name'"});

  const int spring = line_of(kBase, "- name: spring");
  expect_error("type", edit(kBase, "    type: linear_spring\n", ""), spring,
               {"element 'spring'", "missing required key 'type'"});
  expect_error("points", edit(kBase, "    points: [{body: bob, at: [0, 0]}, {body: cart, at: [0.5, 0]}]\n", ""), spring,
               {"element 'spring' (linear_spring)", "missing required key 'points'"});
  expect_error("stiffness", edit(kBase, "    stiffness: 100.0\n", ""), spring,
               {"element 'spring' (linear_spring)", "missing required parameter 'stiffness'"});
  expect_error("damping", edit(kBase, "    damping: 4.0\n", ""), line_of(kBase, "- name: damper"),
               {"element 'damper' (linear_dashpot)", "missing required parameter 'damping'"});
  text = edit(kBase, "- {body: ground, at: [0, 2]}", "- {at: [0, 2]}");
  expect_error("point body", text, line_of(text, "- {at: [0, 2]}"), {"element 'damper'", "point 1", "missing required key 'body'"});
  text = edit(kBase, "- {type: force, body: bob, at: [0.1, 0.0], value: [1.0, -2.0]}", "- {type: force, body: bob}");
  expect_error("load value", text, line_of(text, "- {type: force, body: bob}"), {"force load on 'bob'", "missing required key 'value'"});
}

TEST_CASE("unknown keys are rejected with the closest allowed key", "[model_io]") {
  std::string text = edit(kBase, "units: SI\n", "units: SI\ngravty: [0, 0]\n");
  expect_error("top level", text, line_of(text, "gravty"), {"model: unknown key 'gravty'", "did you mean 'gravity'", "allowed keys"});
  text = edit(kBase, "inertia: 0.5", "inertai: 0.5");
  expect_error("body", text, line_of(text, "inertai"), {"body 'bob'", "unknown key 'inertai'", "did you mean 'inertia'"});
  text = edit(kBase, "stiffness: 100.0", "stifness: 100.0");
  expect_error("element typo", text, line_of(text, "stifness"),
               {"element 'spring' (linear_spring)", "unknown key 'stifness'", "did you mean 'stiffness'", "free_length"});
  text = edit(kBase, "damping: 4.0\n", "damping: 4.0\n    colour: red\n");
  expect_error("element extra key", text, line_of(text, "colour"), {"element 'damper' (linear_dashpot)", "unknown key 'colour'"});
  text = edit(kBase, "axis: [1, 0]", "axes: [1, 0]");
  expect_error("joint typo", text, line_of(text, "axes"), {"element 'slide' (slider_joint)", "did you mean 'axis'"});
  text = edit(kBase, "{body: cart, at: [0.5, 0]}", "{body: cart, offset: [0.5, 0]}");
  expect_error("point", text, line_of(text, "offset"), {"element 'spring' (linear_spring): point 2", "unknown key 'offset'"});
  text = edit(kBase, "value: [1.0, -2.0]}", "value: [1.0, -2.0], scale: 2}");
  expect_error("load", text, line_of(text, "scale"), {"load: unknown key 'scale'"});
  text = edit(kBase, "  dt: 1.0e-4\n", "  dt: 1.0e-4\n  rtoll: 1e-6\n");
  expect_error("simulation", text, line_of(text, "rtoll"), {"simulation: unknown key 'rtoll'", "did you mean 'rtol'"});
  text = edit(kBase, "    mass: 3.0\n", "    mass: 3.0\n    mass: 4.0\n");
  expect_error("repeated key", text, line_of(text, "mass: 4.0"), {"body 'cart'", "'mass' is given twice"});
}

TEST_CASE("unknown element types and body names are rejected with suggestions", "[model_io]") {
  std::string text = edit(kBase, "type: linear_spring", "type: linear_sprin");
  expect_error("type", text, line_of(text, "linear_sprin\n"),
               {"element 'spring'", "unknown element type 'linear_sprin'", "did you mean 'linear_spring'", "pin_joint"});
  text = edit(kBase, "{body: bob, at: [0, 0]}", "{body: bobb, at: [0, 0]}");
  expect_error("point body", text, line_of(text, "bobb"),
               {"element 'spring' (linear_spring): point 1", "unknown body 'bobb'", "did you mean 'bob'", "ground"});
  text = edit(kBase, "    body: cart\n", "    body: kart\n");
  expect_error("load body", text, line_of(text, "kart"), {"moment load on 'kart'", "unknown body 'kart'", "did you mean 'cart'"});
  text = edit(kBase, "    body: cart\n", "    body: ground\n");
  expect_error("load on ground", text, line_of(text, "body: ground\n"), {"a load on the ground does nothing"});
  text = edit(kBase, "type: moment", "type: torque");
  expect_error("load type", text, line_of(text, "torque"), {"unknown type 'torque'", "force or moment"});
  text = edit(kBase, "integrator: euler", "integrator: rk4");
  expect_error("integrator", text, line_of(text, "rk4"), {"integrator must be auto, ida or euler", "rk4"});
}

TEST_CASE("vectors must have the right size", "[model_io]") {
  std::string text = edit(kBase, "position: [1.0, 2.0]", "position: [1.0, 2.0, 3.0]");
  expect_error("position", text, line_of(text, "position: [1.0, 2.0, 3.0]"),
               {"body 'bob': position", "list of 2 numbers", "not a list of 3"});
  text = edit(kBase, "{body: cart, at: [0.5, 0]}", "{body: cart, at: [0.5]}");
  expect_error("point at", text, line_of(text, "at: [0.5]"), {"element 'spring' (linear_spring): point 2: at", "list of 2 numbers"});
  text = edit(kBase, "at: [0.1, 0.0]", "at: [0.1]");
  expect_error("load at", text, line_of(text, "at: [0.1]"), {"force load on 'bob': at", "list of 2 numbers"});
  text = edit(kBase, "units: SI\n", "units: SI\ngravity: [-9.8]\n");
  expect_error("gravity", text, line_of(text, "gravity"), {"gravity must be a list of 2 numbers"});
  text = edit(kBase, "velocity: [1.5, -0.5]", "velocity: 1.5");
  expect_error("velocity scalar", text, line_of(text, "velocity: 1.5"), {"body 'cart': velocity", "list of 2 numbers"});
  text = edit(kBase, "axis: [1, 0]", "axis: [1, 0, 0]");
  expect_error("axis", text, line_of(text, "axis"), {"element 'slide' (slider_joint): 'axis'", "list of 2 numbers"});
  text = edit(kBase, "value: [1.0, -2.0]}", "value: 1.0}");
  expect_error("force value", text, line_of(text, "value: 1.0}"), {"force load on 'bob': value [Fx, Fy]"});
  text = edit(kBase, "      - [1.0, 10.0]\n", "      - [1.0]\n");
  expect_error("table row", text, line_of(text, "- [1.0]"), {"moment load on 'cart': table row 2 must be [t, value]"});
}

TEST_CASE("numbers out of range say which limit they break", "[model_io]") {
  std::string text = edit(kBase, "mass: 1.0", "mass: 0");
  expect_error("zero mass", text, line_of(text, "mass: 0"), {"body 'bob': mass must be positive"});
  text = edit(kBase, "mass: 1.0", "mass: -1.0");
  expect_error("negative mass", text, line_of(text, "mass: -1.0"), {"body 'bob': mass must be positive"});
  text = edit(kBase, "inertia: 0.5", "inertia: -0.5");
  expect_error("negative inertia", text, line_of(text, "inertia: -0.5"), {"body 'bob': inertia must not be negative"});
  text = edit(kBase, "stiffness: 100.0", "stiffness: -100.0");
  expect_error("negative stiffness", text, line_of(text, "stiffness: -100.0"),
               {"element 'spring' (linear_spring)", "'stiffness' must not be negative"});
  text = edit(kBase, "damping: 4.0", "damping: -4.0");
  expect_error("negative damping", text, line_of(text, "damping: -4.0"),
               {"element 'damper' (linear_dashpot)", "'damping' must not be negative"});
  text = edit(kBase, "t_end: 2.0", "t_end: 0");
  expect_error("zero t_end", text, line_of(text, "t_end"), {"simulation: t_end must be positive"});
  text = edit(kBase, "t_end: 2.0", "t_end: -1.0");
  expect_error("negative t_end", text, line_of(text, "t_end"), {"simulation: t_end must be positive"});
  text = edit(kBase, "dt: 1.0e-4", "dt: 0");
  expect_error("zero dt", text, line_of(text, "dt: 0"), {"simulation: dt must be positive"});
  text = edit(kBase, "units: SI", "units: in-lbf-s");
  text = edit(text, "mass: 1.0", "weight: -5");
  expect_error("negative weight", text, line_of(text, "weight"), {"body 'bob': weight must be positive"});
  text = edit(kBase, "free_length: 1.5", "free_length: -1.5");
  expect_error("negative free length", text, line_of(text, "free_length"), {"'free_length' must not be negative"});
}

TEST_CASE("NaN, infinite and non-numeric values are rejected", "[model_io]") {
  std::string text = edit(kBase, "mass: 1.0", "mass: .nan");
  expect_error("nan mass", text, line_of(text, ".nan"), {"body 'bob': mass must be a finite number", ".nan"});
  text = edit(kBase, "stiffness: 100.0", "stiffness: .inf");
  expect_error("inf stiffness", text, line_of(text, ".inf"), {"element 'spring' (linear_spring): 'stiffness' must be a finite number"});
  text = edit(kBase, "position: [1.0, 2.0]", "position: [.NaN, 2.0]");
  expect_error("nan position", text, line_of(text, ".NaN"), {"body 'bob': position entry 1 must be a finite number"});
  text = edit(kBase, "t_end: 2.0", "t_end: .inf");
  expect_error("inf t_end", text, line_of(text, "t_end"), {"simulation: t_end must be a finite number"});
  text = edit(kBase, "      - [1.0, 10.0]\n", "      - [1.0, -.inf]\n");
  expect_error("inf table value", text, line_of(text, "-.inf"), {"table row 2 value must be a finite number"});
  text = edit(kBase, "units: SI\n", "units: SI\ngravity: [0, .nan]\n");
  expect_error("nan gravity", text, line_of(text, "gravity"), {"gravity entry 2 must be a finite number"});

  text = edit(kBase, "mass: 1.0", "mass: heavy");
  expect_error("word mass", text, line_of(text, "heavy"), {"body 'bob': mass must be a number, not 'heavy'"});
  text = edit(kBase, "stiffness: 100.0", "stiffness: [100.0]");
  expect_error("list stiffness", text, line_of(text, "stiffness"), {"'stiffness' must be a number"});
  text = edit(kBase, "position: [1.0, 2.0]", "position: [1.0, up]");
  expect_error("word in position", text, line_of(text, "up]"), {"position entry 2 must be a number, not 'up'"});
  text = edit(kBase, "t_end: 2.0", "t_end:");
  expect_error("empty t_end", text, line_of(text, "t_end"), {"simulation: t_end must be a number"});
  text = edit(kBase, "railcrash: 1", "railcrash: one");
  expect_error("version word", text, 1, {"railcrash (format version) must be a number"});
  text = edit(kBase, "railcrash: 1", "railcrash: 2");
  expect_error("version 2", text, 1, {"reads model format 1", "railcrash: 2"});
  text = edit(kBase, "  dt: 1.0e-4\n", "  dt: 1.0e-4\n  force_dt: perhaps\n");
  expect_error("force_dt", text, line_of(text, "perhaps"), {"simulation: force_dt must be true or false"});
  text = edit(kBase, "  - name: bob\n", "  - name: [bob]\n");
  expect_error("list name", text, line_of(text, "[bob]"), {"body name must be a word"});
}

TEST_CASE("a body's car is a name, bodies without one belong to no car", "[model_io]") {
  const Model model = testing::model_from_text(edit(kBase, "    angular_velocity: 0.2\n", "    angular_velocity: 0.2\n    car: lead car\n"));
  CHECK(model.bodies()[0].car.empty());
  CHECK(model.bodies()[1].car == "lead car");
  const auto with_car = [](const std::string& value) {
    return edit(kBase, "    angular_velocity: 0.2\n", "    angular_velocity: 0.2\n    car: " + value + "\n");
  };
  const int line = line_of(with_car("x"), "    car: x");
  expect_error("empty car", with_car("\"\""), line, {"body 'cart': car must not be empty"});
  expect_error("list car", with_car("[lead]"), line, {"body 'cart': car must be a word"});
  expect_error("car with a comma", with_car("\"lead, front\""), line, {"body 'cart': car 'lead, front' holds the character ','"});
  expect_error("car with spaces around", with_car("\" lead\""), line, {"body 'cart': car ' lead' starts or ends with a space"});
}

TEST_CASE("names must be unique and 'ground' is reserved", "[model_io]") {
  std::string text = edit(kBase, "- name: cart", "- name: bob");
  expect_error("duplicate body", text, line_of(kBase, "- name: cart"), {"body 'bob' is defined twice", "unique"});
  text = edit(kBase, "- name: damper", "- name: spring");
  expect_error("duplicate element", text, line_of(kBase, "- name: damper"),
               {"element 'spring' is defined twice", "first at line " + std::to_string(line_of(kBase, "- name: spring"))});
  text = edit(kBase, "- name: cart", "- name: ground");
  expect_error("ground body", text, line_of(text, "- name: ground"), {"'ground' is reserved", "rename the body"});
}

TEST_CASE("unit systems and weight", "[model_io]") {
  std::string text = edit(kBase, "units: SI", "units: imperial");
  expect_error("units", text, 3, {"units must be SI or in-lbf-s, not 'imperial'"});
  text = edit(kBase, "units: SI", "units: si");
  expect_error("units case", text, 3, {"units must be SI or in-lbf-s"});
  text = edit(kBase, "mass: 1.0", "weight: 10.0");
  expect_error("weight in SI", text, line_of(text, "weight"), {"body 'bob'", "'weight' is for in-lbf-s models", "'mass' in kg"});
  text = edit(edit(kBase, "units: SI", "units: in-lbf-s"), "mass: 1.0", "mass: 1.0\n    weight: 386.088");
  expect_error("mass and weight", text, line_of(text, "weight"), {"body 'bob': give either mass or weight, not both"});
  text = edit(edit(kBase, "units: SI", "units: in-lbf-s"), "    mass: 1.0\n", "");
  expect_error("neither", text, line_of(text, "- name: bob"), {"body 'bob' (give mass or weight)", "missing required key 'mass'"});
}

TEST_CASE("elements need the right points and a usable axis", "[model_io]") {
  std::string text = edit(kBase, "points: [{body: bob, at: [0, 0]}, {body: cart, at: [0.5, 0]}]", "points: [{body: bob}]");
  expect_error("one point", text, line_of(text, "- name: spring"),
               {"element 'spring' (linear_spring) needs exactly 2 points, found 1"});
  text = edit(kBase, "points: [{body: ground, at: [0, 0]}, {body: cart, at: [0, 0]}]",
              "points: [{body: ground}, {body: cart}, {body: bob}]");
  expect_error("three points", text, line_of(text, "- name: slide"), {"element 'slide' (slider_joint) needs exactly 2 points, found 3"});
  text = edit(kBase, "points: [{body: bob, at: [0, 0]}, {body: cart, at: [0.5, 0]}]", "points: []");
  expect_error("no points", text, line_of(text, "- name: spring"), {"needs exactly 2 points, found 0"});
  text = edit(kBase, "points: [{body: bob, at: [0, 0]}, {body: cart, at: [0.5, 0]}]", "points: {body: bob}");
  expect_error("points map", text, line_of(text, "points: {body: bob}"), {"element 'spring' (linear_spring): points must be a list"});
  text = edit(kBase, "axis: [1, 0]", "axis: [0, 0]");
  expect_error("zero axis", text, line_of(text, "axis"), {"element 'slide' (slider_joint)", "axis must be a non-zero direction"});
  text = edit(kBase, "axis: [1, 0]", "axis: [0.0, -0.0]");
  expect_error("signed zero axis", text, line_of(text, "axis"), {"axis must be a non-zero direction"});
  text = edit(kBase, "{body: bob, at: [0, 0]}, {body: cart, at: [0.5, 0]}", "{body: bob, at: [0, 0]}, {body: bob, at: [0, 0]}");
  expect_error("coincident spring points", text, line_of(text, "- name: spring"), {"linear_spring 'spring'", "coincide"});
}

TEST_CASE("an output_interval that would give more than a million rows is refused with the figure", "[model_io]") {
  // t_end 2 / 1e-6 = 2e6 rows; the smallest interval that fits is 2 / 1e6 = 2e-6.
  const std::string text = edit(kBase, "output_interval: 0.01", "output_interval: 1.0e-6");
  expect_error("tiny output interval", text, line_of(text, "output_interval"),
               {"simulation: output_interval 1e-06 with t_end 2 gives 2e+06 output rows, more than the limit 1e+06",
                "use output_interval >= 2e-06"});
  CHECK_NOTHROW(load_model_text(edit(kBase, "output_interval: 0.01", "output_interval: 2.0e-6"), "test.yaml"));
  RunOverrides longer;
  longer.t_end = 1e6;  // 1e8 rows at the model's 0.01
  CHECK_THROWS_WITH(load_model_text(kBase, "test.yaml", {}, option_settings(longer)),
                    Catch::Contains("test.yaml: --t-end 1000000: simulation: output_interval 0.01 with t_end 1e+06 gives 1e+08 output rows"));
}

TEST_CASE("a joint with all its points on one body or on ground is refused at load", "[model_io]") {
  const std::string slide_points = "points: [{body: ground, at: [0, 0]}, {body: cart, at: [0, 0]}]";
  std::string text = edit(kBase, slide_points, "points: [{body: cart, at: [0, 0]}, {body: cart, at: [1, 0]}]");
  expect_error("joint from a body to itself", text, line_of(text, "- name: slide"),
               {"joint 'slide' (slider_joint) has all its points on one body", "constrains nothing"});
  text = edit(kBase, slide_points, "points: [{body: ground, at: [0, 0]}, {body: ground, at: [1, 0]}]");
  expect_error("joint from ground to ground", text, line_of(text, "- name: slide"),
               {"joint 'slide' (slider_joint) has all its points on ground", "two different bodies"});
}

TEST_CASE("tabulated loads need strictly increasing times", "[model_io]") {
  std::string text = edit(kBase, "      - [3.0, -10.0]\n", "      - [1.0, -10.0]\n");
  expect_error("repeated time", text, line_of(text, "- [1.0, -10.0]"),
               {"moment load on 'cart': table row 3", "times must increase strictly"});
  text = edit(kBase, "      - [3.0, -10.0]\n", "      - [0.5, -10.0]\n");
  expect_error("decreasing time", text, line_of(text, "- [0.5, -10.0]"), {"table row 3", "times must increase strictly"});
  text = edit(kBase, "value: [1.0, -2.0]}", "value: [[0.0, 1.0, 1.0], [0.0, 2.0, 2.0]]}");
  expect_error("force table", text, line_of(text, "value: [[0.0"), {"force load on 'bob': table row 2", "times must increase"});
  text = edit(kBase, "      - [1.0, 10.0]\n", "      - [1.0, 10.0, 5.0]\n");
  expect_error("moment row of 3", text, line_of(text, "10.0, 5.0"), {"table row 2 must be [t, value]"});
}

TEST_CASE("structural problems: empty lists, wrong section shapes, offset loads on point masses", "[model_io]") {
  std::string text = edit(kBase, kBodies, "bodies: []\n");
  expect_error("no bodies", text, line_of(text, "bodies: []"), {"add at least one body"});
  text = edit(kBase, kBodies, "bodies:\n  name: bob\n");
  expect_error("bodies map", text, line_of(text, "  name: bob"), {"bodies must be a list"});
  text = edit(kBase, kSimulation, "simulation: 2.0\n");
  expect_error("simulation scalar", text, line_of(text, "simulation: 2.0"), {"simulation must be a map"});
  text = edit(kBase, "  - name: bob\n    mass: 1.0\n    inertia: 0.5\n    position: [1.0, 2.0]\n", "  - bob\n");
  expect_error("body scalar", text, line_of(text, "- bob"), {"each body must be a map"});
  text = edit(kBase, "inertia: 0.5", "inertia: 0");
  expect_error("offset load on point mass", text, line_of(text, "- {type: force"), {"body 'bob'", "zero inertia"});
}

// ---------------------------------------------------------------------------------------
// Robustness: no input crashes, hangs or leaks a non-InputError exception
// ---------------------------------------------------------------------------------------

TEST_CASE("truncated and edited files are either loaded or rejected with an InputError", "[model_io]") {
  int rejected = 0, loaded = 0;
  const auto try_load = [&](const std::string& text) {
    try {
      (void)load_model_text(text, "test.yaml");
      ++loaded;
    } catch (const InputError& e) {
      ++rejected;
      const std::string message = e.what();
      if (message.rfind("test.yaml:", 0) != 0) FAIL_CHECK("message without the file name: " << message << "\nfor:\n" << text);
    } catch (const std::exception& e) {
      FAIL_CHECK("not an InputError: " << e.what() << "\nfor:\n" << text);
    }
  };
  // Every prefix of the file (cuts inside keys, lists, flow maps, ...).
  for (std::size_t n = 0; n < kBase.size(); ++n) try_load(kBase.substr(0, n));
  // Every line left out, and every line doubled.
  std::vector<std::string> lines;
  for (std::size_t start = 0; start < kBase.size();) {
    const auto end = kBase.find('\n', start);
    lines.push_back(kBase.substr(start, end - start + 1));
    start = end + 1;
  }
  for (std::size_t skip = 0; skip < lines.size(); ++skip) {
    std::string without, doubled;
    for (std::size_t i = 0; i < lines.size(); ++i) {
      if (i != skip) without += lines[i];
      doubled += lines[i];
      if (i == skip) doubled += lines[i];
    }
    try_load(without);
    try_load(doubled);
  }
  // Each character replaced by YAML punctuation.
  for (std::size_t i = 0; i < kBase.size(); i += 3)
    for (const char c : {'[', '{', ':', '-', '#', '\'', '&', '*'}) {
      std::string text = kBase;
      text[i] = c;
      try_load(text);
    }
  CHECK(rejected > 1000);
  CHECK(loaded > 10);
}

// ---------------------------------------------------------------------------------------
// 3. Redundant and contradictory constraints
// ---------------------------------------------------------------------------------------

namespace {
const std::string kBar = R"(  - name: bar
    mass: 1.0
    inertia: 0.1
    position: [1.0, 0.0]
)";
const std::string kPinA = R"(  - name: pin_a
    type: pin_joint
    points: [{body: ground, at: [0, 0]}, {body: bar, at: [-1, 0]}]
)";
const std::string kPinB = R"(  - name: pin_b
    type: pin_joint
    points: [{body: ground, at: [0, 0]}, {body: bar, at: [-1, 0]}]
)";
const std::string kWeld = R"(  - name: weld
    type: rigid_joint
    points: [{body: ground, at: [0, 0]}, {body: bar, at: [-1, 0]}]
)";
}  // namespace

TEST_CASE("a properly constrained model assembles", "[model_io]") {
  const Model model = testing::model_from_text(single_body_model(kBar, kPinA));
  DaeSystem system(model);
  std::vector<double> y = system.initial_state();
  CHECK_NOTHROW(check_constraint_rank(system, y.data()));
  const AssemblyReport report = assemble_initial_state(system, y);
  CHECK(report.largest_position_change < 1e-12);

  const Model crank = load_model(std::string(RAILCRASH_SOURCE_DIR) + "/verification/cases/slider_crank.yaml").model;
  DaeSystem crank_system(crank);
  std::vector<double> yc = crank_system.initial_state();
  CHECK_NOTHROW(assemble_initial_state(crank_system, yc));
}

TEST_CASE("redundant joints are InputErrors naming the elements", "[model_io]") {
  SECTION("two pins at the same ground point plus a rigid joint") {
    const std::string text = single_body_model(kBar, kPinA + kPinB + kWeld);
    const std::string message = assembly_error(text);
    INFO(message);
    CHECK_THAT(message, StartsWith("test.yaml: ") && Contains("redundant") && Contains("4 of the 7 constraint equations"));
    CHECK_THAT(message, Contains("'pin_b' (pin_joint, line " + std::to_string(line_of(text, "- name: pin_b")) + ")"));
    CHECK_THAT(message, Contains("'weld' (rigid_joint, line " + std::to_string(line_of(text, "- name: weld")) + ")"));
    CHECK_THAT(message, Contains("Remove one of them"));
    // check_constraint_rank alone says the same.
    const Model model = testing::model_from_text(text);
    DaeSystem system(model);
    const std::vector<double> y = system.initial_state();
    CHECK_THROWS_WITH(check_constraint_rank(system, y.data()), Contains("redundant") && Contains("'weld'"));
  }
  SECTION("a body pinned twice at the same point") {
    const std::string text = single_body_model(kBar, kPinA + kPinB);
    const std::string message = assembly_error(text);
    INFO(message);
    CHECK_THAT(message, Contains("redundant") && Contains("2 of the 4 constraint equations") && Contains("'pin_b' (pin_joint"));
  }
  SECTION("a rigid joint and a pin on the same body") {
    const std::string message = assembly_error(single_body_model(kBar, kWeld + kPinA));
    INFO(message);
    CHECK_THAT(message, Contains("redundant") && Contains("2 of the 5 constraint equations") && Contains("'pin_a'"));
  }
}

TEST_CASE("contradictory joints are InputErrors naming the elements", "[model_io]") {
  SECTION("a two-link chain pinned to ground at points further apart than it can reach") {
    const std::string text = R"(railcrash: 1
name: chain too short
units: SI
bodies:
  - name: link_a
    mass: 1.0
    inertia: 0.1
    position: [1.0, 0.5]
    angle: 0.3
  - name: link_b
    mass: 1.0
    inertia: 0.1
    position: [4.0, 0.5]
    angle: -0.3
elements:
  - name: left_pin
    type: pin_joint
    points: [{body: ground, at: [0, 0]}, {body: link_a, at: [-1, 0]}]
  - name: middle_pin
    type: pin_joint
    points: [{body: link_a, at: [1, 0]}, {body: link_b, at: [-1, 0]}]
  - name: right_pin
    type: pin_joint
    points: [{body: ground, at: [6, 0]}, {body: link_b, at: [1, 0]}]
simulation:
  t_end: 1.0
)";
    const std::string message = assembly_error(text);
    INFO(message);
    CHECK_THAT(message, StartsWith("test.yaml:") && Contains("the joints cannot all be satisfied") && Contains("'middle_pin'") &&
                            Contains("contradict"));
  }
  SECTION("a pivoted bar whose end should slide on a line out of its reach") {
    const std::string text = single_body_model(R"(  - name: bar
    mass: 1.0
    inertia: 0.1
    position: [0.0, 0.0]
    angle: 0.5
)",
                                               R"(  - name: pivot
    type: pin_joint
    points: [{body: ground, at: [0, 0]}, {body: bar, at: [0, 0]}]
  - name: guide
    type: sliding_pin_joint
    axis: [1, 0]
    points: [{body: ground, at: [0, 3]}, {body: bar, at: [1, 0]}]
)");
    const std::string message = assembly_error(text);
    INFO(message);
    CHECK_THAT(message, StartsWith("test.yaml:" + std::to_string(line_of(text, "- name: guide")) + ": ") &&
                            Contains("the joints cannot all be satisfied") && Contains("sliding_pin_joint 'guide'"));
  }
  SECTION("a body pinned to ground at two points further apart than its attachment points") {
    // 4 equations on 3 coordinates: this is caught as redundant before assembly is tried
    // (see the final report); either way it must be an InputError naming a joint.
    const std::string text = single_body_model(R"(  - name: bar
    mass: 1.0
    inertia: 0.1
    position: [0.0, 0.0]
)",
                                               R"(  - name: left_pin
    type: pin_joint
    points: [{body: ground, at: [-1, 0]}, {body: bar, at: [-1, 0]}]
  - name: right_pin
    type: pin_joint
    points: [{body: ground, at: [2, 0]}, {body: bar, at: [1, 0]}]
)");
    const std::string message = assembly_error(text);
    INFO(message);
    CHECK_THAT(message, StartsWith("test.yaml:") && (Contains("cannot all be satisfied") || Contains("redundant")) &&
                            (Contains("'left_pin'") || Contains("'right_pin'")));
  }
}

namespace {

// Two 40 t cars of a modern multiple unit, each driven at 5 m/s into its own crush zone on a
// fixed barrier; the crush curve, the unloading stiffness and the velocity are written once
// (&anchor) and used again (*alias), as PyYAML writes a list object a generator reuses.
const std::string kSharedValuesModel = R"(railcrash: 1
name: two cars on one crush zone definition
units: SI
gravity: [0, 0]
bodies:
  - {name: car_a, mass: 40000, inertia: 1.0e6, position: [1.0, 0], velocity: &speed [-5, 0]}
  - {name: car_b, mass: 40000, inertia: 1.0e6, position: [1.0, 10], velocity: *speed}
elements:
  - name: crush_a
    type: crush_spring
    free_length: 1.0
    curve: &zone [[0, 0], [0.01, 1.5e6], [0.6, 1.5e6]]
    unloading_stiffness: &unloading 4.0e8  # at least every edited curve's steepest slope
    points: [{body: ground, at: [0, 0]}, {body: car_a, at: [0, 0]}]
  - name: crush_b
    type: crush_spring
    free_length: 1.0
    curve: *zone
    unloading_stiffness: *unloading
    points: [{body: ground, at: [0, 10]}, {body: car_b, at: [0, 0]}]
simulation: {t_end: 0.4, rtol: 1.0e-8, output_interval: 0.0001}
)";

const CrushSpring& crush_spring(const Model& model, std::size_t index) {
  const auto* spring = dynamic_cast<const CrushSpring*>(model.elements()[index].get());
  REQUIRE(spring != nullptr);
  return *spring;
}

}  // namespace

TEST_CASE("an edit changes exactly the key it names, also where an alias shares the value", "[model_io]") {
  const std::vector<double> soft{0.0, 1.5e6, 1.5e6}, stiff{0.0, 3.0e6, 3.0e6};
  const Model as_written = load_model_text(kSharedValuesModel, "shared.yaml").model;
  CHECK(crush_spring(as_written, 0).curve_force == soft);
  CHECK(crush_spring(as_written, 1).curve_force == soft);
  CHECK(as_written.bodies()[1].vx == -5.0);

  SECTION("KEY=VALUE on a shared list") {
    const Model model = load_model_text(kSharedValuesModel, "shared.yaml", {"elements.crush_a.curve=[[0, 0], [0.01, 3.0e6], [0.6, 3.0e6]]"}).model;
    CHECK(crush_spring(model, 0).curve_force == stiff);
    CHECK(crush_spring(model, 1).curve_force == soft);
  }
  SECTION("KEY*=FACTOR on a shared number") {
    const Model model = load_model_text(kSharedValuesModel, "shared.yaml", {"elements.crush_b.unloading_stiffness*=2"}).model;
    CHECK(crush_spring(model, 0).unloading_stiffness == 4.0e8);
    CHECK(crush_spring(model, 1).unloading_stiffness == 8.0e8);
  }
  SECTION("KEY=VALUE and KEY[i] on a shared body velocity") {
    const Model whole = load_model_text(kSharedValuesModel, "shared.yaml", {"bodies.car_a.velocity=[-6, 0]"}).model;
    CHECK(whole.bodies()[0].vx == -6.0);
    CHECK(whole.bodies()[1].vx == -5.0);
    const Model entry = load_model_text(kSharedValuesModel, "shared.yaml", {"bodies.car_b.velocity[0]=-4", "bodies.car_b.velocity[0]*=0.5"}).model;
    CHECK(entry.bodies()[0].vx == -5.0);
    CHECK(entry.bodies()[1].vx == -2.0);
    CHECK(entry.bodies()[1].vy == 0.0);
  }
  SECTION("an entry of a shared table, and a second edit below the first") {
    const Model model = load_model_text(kSharedValuesModel, "shared.yaml",
                                        {"elements.crush_a.curve[2]=[0.8, 1.5e6]", "elements.crush_a.curve[1][1]=2.0e6"}).model;
    CHECK(crush_spring(model, 0).curve_crush == std::vector<double>{0.0, 0.01, 0.8});
    CHECK(crush_spring(model, 0).curve_force == std::vector<double>{0.0, 2.0e6, 1.5e6});
    CHECK(crush_spring(model, 1).curve_crush == std::vector<double>{0.0, 0.01, 0.6});
    CHECK(crush_spring(model, 1).curve_force == soft);
  }
  SECTION("a variant's set goes through the same path") {
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("railcrash_alias_variant_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "base.yaml") << kSharedValuesModel;
    std::ofstream(dir / "variant.yaml") << "railcrash: 1\nvariant_of: base.yaml\nset:\n  elements.crush_b.curve: [[0, 0], [0.01, 3.0e6], [0.6, 3.0e6]]\n";
    const Model model = load_model((dir / "variant.yaml").string()).model;
    std::filesystem::remove_all(dir);
    CHECK(crush_spring(model, 0).curve_force == soft);
    CHECK(crush_spring(model, 1).curve_force == stiff);
  }
}

TEST_CASE("KEY[i] settings name an entry of a list: each applies to the document as the settings before it left it", "[model_io]") {
  const std::string model_text = kHeader + "gravity: [0, -9.81]\n" + kBodies + kElements + kLoads + kSimulation;
  const Model model = load_model_text(model_text, "test.yaml", {"bodies.cart.velocity=[3, 0.5]", "bodies.cart.velocity[0]=2",
                                                                "bodies.cart.velocity[1]*=4", "gravity[1]=-1.62"}).model;
  const auto cart = std::find_if(model.bodies().begin(), model.bodies().end(), [](const Body& b) { return b.name == "cart"; });
  REQUIRE(cart != model.bodies().end());
  CHECK(cart->vx == 2.0);
  CHECK(cart->vy == 2.0);
  CHECK(model.gravity_y == -1.62);
  const auto error = [&](const std::string& setting) {
    try {
      (void)load_model_text(model_text, "test.yaml", {setting});
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CHECK_THAT(error("bodies.cart.velocity[2]=1"), StartsWith("test.yaml: --set 'bodies.cart.velocity[2]=1': ") &&
                                                     Contains("the list at 'bodies.cart.velocity' has 2 entries (index from 0)"));
  CHECK_THAT(error("bodies.cart.mass[0]=1"), Contains("the model has no list at 'bodies.cart.mass'"));
  CHECK_THAT(error("bodies.cart.velocity[x]=1"), Contains("write an entry of a list as KEY[INDEX]"));
  CHECK_THAT(error("gravity[2]*=2"), Contains("the list at 'gravity' has 2 entries"));
  // An entry that is 0 is refused a factor, as a key that is 0 is.
  CHECK_THROWS_AS(load_model_text(model_text, "test.yaml", {"elements.slide.axis[1]*=2"}), ZeroScaledError);
  CHECK_THAT(error("gravity[0]*=2"), Contains("'gravity[0]' is 0 in the model, so a factor changes nothing"));
}


TEST_CASE("a name longer than 256 characters is refused at load with its file and line and start and length and the limit", "[model_io]") {
  const std::string long_name(20000, 'e');
  const std::string start(40, 'e');
  expect_error("element", edit(kBase, "- name: damper", "- name: " + long_name), line_of(kBase, "- name: damper"),
               {"element name '" + start + "...'", "is 20000 characters long", "limit of 256", "shorten it"});
  expect_error("body", edit(kBase, "- name: cart", "- name: c" + long_name), line_of(kBase, "- name: cart"),
               {"body name 'c", "is 20001 characters long", "limit of 256"});
  expect_error("model", edit(kBase, "name: io test model", "name: " + long_name), line_of(kBase, "name: io test model"),
               {"the model's name", "20000 characters long"});
  // Characters, not bytes: 256 two-byte letters are at the limit, one more is past it.
  std::string umlauts;
  for (int k = 0; k < 256; ++k) umlauts += "\xc3\xa4";
  CHECK(name_length_problem("body name", umlauts).empty());
  CHECK_THAT(name_length_problem("body name", umlauts + "x"), Contains("257 characters long"));
  CHECK(name_length_problem("body name", std::string(kMaxNameLength, 'b')).empty());
}

TEST_CASE("every body point (an element's, a load's, a crush gauge's, an output's) names an unknown body alike", "[model_io]") {
  // One reading of a point's body and offset: before, a crush gauge's point said only "unknown body".
  const std::string gauge = "responses:\n  reference_crush: 1.0\n  crush_gauges:\n"
                            "    - {name: g, points: [{body: bobb, at: [0, 0]}, {body: cart, at: [0.5, 0]}]}\n";
  std::string text = kBase + gauge;
  expect_error("crush gauge point body", text, line_of(text, "bobb"),
               {"responses: crush gauge 1: point 1: unknown body 'bobb' (did you mean 'bob'?); bodies are: ground, bob, cart"});
  text = edit(kBase, "{body: bob, at: [0, 0]}", "{body: bobb, at: [0, 0]}");
  expect_error("element point body", text, line_of(text, "bobb"),
               {"element 'spring' (linear_spring): point 1: unknown body 'bobb' (did you mean 'bob'?); bodies are: ground, bob, cart"});
  // Where the ground will not do, it is not offered.
  text = kBase + "outputs:\n  - {body: cartt, at: [0.5, 0]}\n";
  expect_error("output body", text, line_of(text, "cartt"),
               {"outputs: item 1: unknown body 'cartt' (did you mean 'cart'?); bodies are: bob, cart"});
  text = edit(kBase, "    body: cart\n", "    body: kart\n");
  expect_error("load body", text, line_of(text, "kart"),
               {"moment load on 'kart': unknown body 'kart' (did you mean 'cart'?); bodies are: bob, cart"});
  text = kBase + "outputs:\n  - {body: ground}\n";
  expect_error("output on ground", text, line_of(text, "ground}"), {"outputs: item 1: the ground does not move; name a body"});
  // The offsets are read the same way: the gauge's second point at the spring's end on the cart.
  const LoadedModel loaded = load_model_text(kBase + "responses:\n  reference_crush: 1.0\n  crush_gauges:\n"
                                              "    - {name: g, points: [{body: bob, at: [0.25, -1]}, {body: cart, at: [0.5, 0]}]}\n",
                                      "test.yaml");
  const Model& model = loaded.model;
  const CrushGauge& g = loaded.run_spec.responses.crush_gauges.at(0);
  CHECK(g.front.body == 0);
  CHECK(g.front.sx == 0.25);
  CHECK(g.front.sy == -1.0);
  CHECK(g.rear.body == 1);
  CHECK(g.rear.sx == model.elements()[0]->point(1).sx);
}

TEST_CASE("every check of rtol gives the one message, naming where the value came from", "[model_io]") {
  const std::string message = " must be a positive number (the relative tolerance; typical: 1e-6), not ";
  CHECK(rtol_problem(1e-6, "rtol").empty());
  CHECK(rtol_problem(0.0, "rtol") == "rtol" + message + "0");
  CHECK(rtol_problem(-1e-3, "--rtol") == "--rtol" + message + "-0.001");
  CHECK_FALSE(rtol_problem(std::numeric_limits<double>::infinity(), "rtol").empty());
  CHECK_FALSE(rtol_problem(std::numeric_limits<double>::quiet_NaN(), "rtol").empty());
  std::string text = edit(kBase, "  dt: 1.0e-4\n", "  dt: 1.0e-4\n  rtol: -1\n");
  expect_error("model file", text, line_of(text, "rtol"), {"simulation: rtol" + message + "-1"});
  CHECK(load_error(kBase, {"simulation.rtol=0"}) == "test.yaml: --set 'simulation.rtol=0': simulation: rtol" + message + "0");
  RunOverrides overrides;
  overrides.rtol = -2.0;
  CHECK_THROWS_WITH(load_model_text(kBase, "test.yaml", {}, option_settings(overrides)),
                    "test.yaml: --rtol -2: simulation: rtol" + message + "-2");
  CHECK_THROWS_WITH(load_model_text(kBase, "test.yaml", {}, option_settings(overrides, OverrideSource::RunSettings)),
                    "test.yaml: RunSettings.rtol = -2: simulation: rtol" + message + "-2");
}

TEST_CASE("the integrators' names come from one table: auto, ida, euler", "[model_io]") {
  CHECK(integrator_names() == std::vector<std::string>{"auto", "ida", "euler"});
  CHECK(integrator_names_text() == "auto, ida or euler");
  CHECK(integrator_names_text("\"") == "\"auto\", \"ida\" or \"euler\"");
  for (const IntegratorName& entry : kIntegratorNames) {
    CHECK(std::string(integrator_name(entry.kind)) == entry.name);
    CHECK(integrator_from_name(entry.name) == entry.kind);
  }
  CHECK_FALSE(integrator_from_name("IDA"));
  CHECK_FALSE(integrator_from_name("ida+euler"));
  const std::string text = edit(kBase, "integrator: euler", "integrator: rk4");
  expect_error("model file", text, line_of(text, "rk4"), {"simulation: integrator must be auto, ida or euler, not 'rk4'"});
}
