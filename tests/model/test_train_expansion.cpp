// Car types and trains (train_expansion.hpp): the expansion's names and places, checked against
// positions worked out by hand and against a flat model written independently; errors naming
// the type's and the instance's lines; settings on a type and on one instance; the mm-t-s-N
// unit system against the same model in SI; the example models in models/examples/.
#include <catch2/catch.hpp>

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "railcrash/model/model_io.hpp"
#include "railcrash/results/run.hpp"
#include "railcrash/scenarios/consist.hpp"
#include "support.hpp"

using namespace railcrash;
using Catch::Matchers::Contains;

namespace {

// A car type of two bodies (car coordinates: front interface at x = 4.5, rear at x = -4.0, so
// 8.5 over the interfaces) and a train of three: car1, mid (named), car3 (reversed), 0.2 apart.
const std::string kTrainModel = R"(railcrash: 1
name: three coaches
units: SI
gravity: [0, 0]
car_types:
  coach:
    bodies:
      - {name: body, mass: 1000, inertia: 100, position: [0.5, 1.0]}
      - {name: nose, mass: 10, inertia: 1, position: [4.0, 1.0]}
    elements:
      - {name: crush, type: crush_spring, curve: [[0, 0], [0.1, 1000]], unloading_stiffness: 1.0e5, points: [{body: nose}, {body: body, at: [2.5, 0]}]}
      - {name: guide, type: slider_joint, axis: [1, 0], points: [{body: body, at: [3.5, 0.0]}, {body: nose}]}
      - {name: rail, type: slider_joint, points: [{body: ground, at: [0.5, 1.0]}, {body: body}]}
    interfaces:
      front: {body: nose, at: [0.5, 0]}
      rear: {body: body, at: [-4.5, 0]}
interface_types:
  bar:
    elements:
      - {name: spring, type: linear_spring, stiffness: 1.0e6, points: [{end: 1, at: [-0.1, 0]}, {end: 2, at: [0.1, 0]}]}
trains:
  - name: unitA
    front: 10.0
    speed: 2.0
    coupling: {type: bar, gap: 0.2}
    cars:
      - {type: coach}
      - {type: coach, name: mid}
      - {type: coach, reversed: true}
simulation:
  t_end: 0.05
)";

const Body& body(const Model& model, const std::string& name) {
  const auto index = model.find_body(name);
  REQUIRE(index);
  return model.bodies()[static_cast<std::size_t>(*index)];
}

const Element& element(const Model& model, const std::string& name) {
  for (const auto& e : model.elements())
    if (e->name() == name) return *e;
  FAIL("no element " << name);
  throw;
}

std::string write_temp(const std::string& name, const std::string& text) {
  const std::string path = (testing::temp_path(name)).string();
  std::ofstream(path) << text;
  return path;
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  REQUIRE(at != std::string::npos);
  return text.replace(at, from.size(), to);
}

}  // namespace

TEST_CASE("a 3-car train expands into named bodies placed one after another, the reversed car mirrored", "[trains]") {
  const Model model = testing::model_from_text(kTrainModel);
  REQUIRE(model.body_count() == 6);
  // car1: not reversed, its front interface (car x 4.5) at x = 10: car coordinates + 5.5.
  CHECK(body(model, "unitA.car1.body").x == Approx(6.0));
  CHECK(body(model, "unitA.car1.nose").x == Approx(9.5));
  // mid: its front 0.2 behind car1's rear (5.5 - 4.0 = 1.5): at 1.3, so car coordinates - 3.2.
  CHECK(body(model, "unitA.mid.body").x == Approx(-2.7));
  CHECK(body(model, "unitA.mid.nose").x == Approx(0.8));
  // car3, reversed: its rear leads, 0.2 behind mid's rear (-7.2): x = -11.4 - car x.
  CHECK(body(model, "unitA.car3.body").x == Approx(-11.9));
  CHECK(body(model, "unitA.car3.nose").x == Approx(-15.4));
  for (const Body& b : model.bodies()) {
    CHECK(b.y == Approx(1.0));
    CHECK(b.vx == Approx(2.0));  // the train's speed along +x
    CHECK(b.car == b.name.substr(0, b.name.rfind('.')));
  }
  // The reversed car's body-frame offsets are mirrored; the others' kept.
  CHECK(element(model, "unitA.car1.crush").points()[1].sx == Approx(2.5));
  CHECK(element(model, "unitA.car3.crush").points()[1].sx == Approx(-2.5));
  // A point on ground follows the car: x of the car's body.
  CHECK(element(model, "unitA.car3.rail").points()[0].sx == Approx(-11.9));
  // Couplings: end 1 is the end at smaller x; 0.1 inside each end, so 0.2 + 0.2 apart.
  const Element& c1 = element(model, "unitA.coupling1.spring");
  CHECK(model.bodies()[static_cast<std::size_t>(c1.points()[0].body)].name == "unitA.mid.nose");
  CHECK(c1.points()[0].sx == Approx(0.4));
  CHECK(model.bodies()[static_cast<std::size_t>(c1.points()[1].body)].name == "unitA.car1.body");
  CHECK(c1.points()[1].sx == Approx(-4.4));
  const Element& c2 = element(model, "unitA.coupling2.spring");
  CHECK(model.bodies()[static_cast<std::size_t>(c2.points()[0].body)].name == "unitA.car3.body");
  CHECK(c2.points()[0].sx == Approx(4.4));  // the reversed car's rear interface, mirrored, 0.1 inside
  CHECK(model.bodies()[static_cast<std::size_t>(c2.points()[1].body)].name == "unitA.mid.body");
  CHECK(c2.points()[1].sx == Approx(-4.4));
}

TEST_CASE("the expanded text mirrors a reversed car's directions and lists the cars", "[trains]") {
  const std::string path = write_temp("railcrash_trains_expand.yaml", kTrainModel);
  const ExpandedModel expanded = expand_model_file(path, {});
  REQUIRE(expanded.cars.size() == 3);
  CHECK(expanded.cars[1].name == "unitA.mid");
  CHECK(expanded.cars[2].reversed);
  CHECK(expanded.cars[2].leading_x == Approx(-7.4));
  CHECK(expanded.cars[2].trailing_x == Approx(-15.9));
  const YAML::Node flat = YAML::Load(expanded.text);
  CHECK(!flat["car_types"]);
  CHECK(!flat["trains"]);
  std::map<std::string, double> axis_x;
  for (const YAML::Node& e : flat["elements"])
    if (e["axis"]) axis_x[e["name"].as<std::string>()] = e["axis"][0].as<double>();
  CHECK(axis_x.at("unitA.car1.guide") == 1.0);
  CHECK(axis_x.at("unitA.car3.guide") == -1.0);
  // The written model loads to the same bodies.
  const Model again = load_model_text(expanded.text, "expanded.yaml").model;
  const Model model = testing::model_from_text(kTrainModel);
  REQUIRE(again.body_count() == model.body_count());
  for (std::size_t i = 0; i < model.bodies().size(); ++i) {
    CHECK(again.bodies()[i].name == model.bodies()[i].name);
    CHECK(again.bodies()[i].x == model.bodies()[i].x);
  }
  std::filesystem::remove(path);
}

TEST_CASE("a 2-car train equals the same model written flat by hand", "[trains]") {
  std::string two_cars = replaced(kTrainModel, "      - {type: coach, reversed: true}\n", "");
  two_cars = replaced(two_cars, "gap: 0.2", "gap: 0.3");
  // Written independently: car1 as above; car2's front 0.3 behind car1's rear (1.5): 1.2, so
  // its car coordinates shifted by 1.2 - 4.5 = -3.3.
  const std::string flat = R"(railcrash: 1
name: three coaches
units: SI
gravity: [0, 0]
bodies:
  - {name: unitA.car1.body, car: unitA.car1, mass: 1000, inertia: 100, position: [6.0, 1.0], velocity: [2, 0]}
  - {name: unitA.car1.nose, car: unitA.car1, mass: 10, inertia: 1, position: [9.5, 1.0], velocity: [2, 0]}
  - {name: unitA.mid.body, car: unitA.mid, mass: 1000, inertia: 100, position: [-2.8, 1.0], velocity: [2, 0]}
  - {name: unitA.mid.nose, car: unitA.mid, mass: 10, inertia: 1, position: [0.7, 1.0], velocity: [2, 0]}
elements:
  - {name: unitA.car1.crush, type: crush_spring, curve: [[0, 0], [0.1, 1000]], unloading_stiffness: 1.0e5, points: [{body: unitA.car1.nose}, {body: unitA.car1.body, at: [2.5, 0]}]}
  - {name: unitA.car1.guide, type: slider_joint, axis: [1, 0], points: [{body: unitA.car1.body, at: [3.5, 0.0]}, {body: unitA.car1.nose}]}
  - {name: unitA.car1.rail, type: slider_joint, points: [{body: ground, at: [6.0, 1.0]}, {body: unitA.car1.body}]}
  - {name: unitA.mid.crush, type: crush_spring, curve: [[0, 0], [0.1, 1000]], unloading_stiffness: 1.0e5, points: [{body: unitA.mid.nose}, {body: unitA.mid.body, at: [2.5, 0]}]}
  - {name: unitA.mid.guide, type: slider_joint, axis: [1, 0], points: [{body: unitA.mid.body, at: [3.5, 0.0]}, {body: unitA.mid.nose}]}
  - {name: unitA.mid.rail, type: slider_joint, points: [{body: ground, at: [-2.8, 1.0]}, {body: unitA.mid.body}]}
  - {name: unitA.coupling1.spring, type: linear_spring, stiffness: 1.0e6, points: [{body: unitA.mid.nose, at: [0.4, 0]}, {body: unitA.car1.body, at: [-4.4, 0]}]}
loads:
  - {type: force, body: unitA.car1.nose, value: [[0, [0, 0]], [0.01, [-2.0e3, 0]]]}
simulation:
  t_end: 0.05
)";
  two_cars += "loads:\n  - {type: force, body: unitA.car1.nose, value: [[0, [0, 0]], [0.01, [-2.0e3, 0]]]}\n";
  const LoadedModel expanded_loaded = testing::loaded_from_text(two_cars);
  const Model& expanded = expanded_loaded.model;
  const LoadedModel by_hand_loaded = testing::loaded_from_text(flat);
  const Model& by_hand = by_hand_loaded.model;
  REQUIRE(expanded.body_count() == by_hand.body_count());
  for (std::size_t i = 0; i < by_hand.bodies().size(); ++i) {
    const Body &a = expanded.bodies()[i], &b = by_hand.bodies()[i];
    CHECK(a.name == b.name);
    CHECK(a.car == b.car);
    CHECK(a.mass == b.mass);
    CHECK(a.inertia == b.inertia);
    CHECK(a.x == Approx(b.x).margin(1e-12));
    CHECK(a.y == b.y);
    CHECK(a.vx == b.vx);
  }
  REQUIRE(expanded.elements().size() == by_hand.elements().size());
  for (std::size_t e = 0; e < by_hand.elements().size(); ++e) {
    const Element &a = *expanded.elements()[e], &b = *by_hand.elements()[e];
    CHECK(a.name() == b.name());
    CHECK(a.type() == b.type());
    REQUIRE(a.points().size() == b.points().size());
    for (std::size_t k = 0; k < a.points().size(); ++k) {
      CHECK(a.points()[k].body == b.points()[k].body);
      CHECK(a.points()[k].sx == Approx(b.points()[k].sx).margin(1e-12));
      CHECK(a.points()[k].sy == b.points()[k].sy);
    }
  }
  // The parameters: the two runs (the nose pushed in, crushing and moving the train) agree.
  const RunOutcome run_expanded = testing::simulate(expanded_loaded, 0.01), run_by_hand = testing::simulate(by_hand_loaded, 0.01);
  REQUIRE(run_expanded.y.size() == run_by_hand.y.size());
  for (std::size_t i = 0; i < run_by_hand.y.size(); ++i) CHECK(run_expanded.y[i] == Approx(run_by_hand.y[i]).margin(1e-9));
  CHECK(run_by_hand.y[1 * 3] < 9.5 + 2.0 * 0.05 - 1e-4);  // the nose did move back on car1: the crush acted
}

TEST_CASE("an error in a car type's element names the type's line and the instance's line", "[trains]") {
  const std::string bad = replaced(kTrainModel, "unloading_stiffness: 1.0e5", "unloading_stiffness: -1.0e5");
  // The crush element is on line 11 of the type named on line 6; car1 is placed on line 27.
  CHECK_THROWS_WITH(testing::model_from_text(bad), Contains("test.yaml:11: element 'unitA.car1.crush' (crush_spring)") &&
                                                       Contains("'unloading_stiffness' must be positive") &&
                                                       Contains("(car type 'coach', line 6; instance unitA.car1, line 27)"));
  // An unknown car type: the line of the train's `type`, with the nearest name.
  CHECK_THROWS_WITH(testing::model_from_text(replaced(kTrainModel, "{type: coach, name: mid}", "{type: coch, name: mid}")),
                    Contains("test.yaml:28: train 'unitA': car 2: type: no car type 'coch' (did you mean 'coach'?)"));
  // A point on a body the car type does not have.
  CHECK_THROWS_WITH(testing::model_from_text(replaced(kTrainModel, "{body: nose}, {body: body, at: [2.5, 0]}",
                                                      "{body: nose}, {body: bdy, at: [2.5, 0]}")),
                    Contains("test.yaml:11: car type 'coach': element 'crush': point 2: no body 'bdy' in the car type (did you mean 'body'?)"));
  // A coupling of an interface type that does not exist.
  CHECK_THROWS_WITH(testing::model_from_text(replaced(kTrainModel, "{type: bar, gap: 0.2}", "{type: bra, gap: 0.2}")),
                    Contains("test.yaml:25: train 'unitA': coupling 1: type: no interface type 'bra' (did you mean 'bar'?)"));
  // Interface elements' errors name the coupling instance.
  CHECK_THROWS_WITH(testing::model_from_text(replaced(kTrainModel, "stiffness: 1.0e6", "stiffness: -1")),
                    Contains("test.yaml:20: element 'unitA.coupling1.spring' (linear_spring)") &&
                        Contains("(interface type 'bar', line 18; coupling unitA.coupling1 (line 25))"));
}

TEST_CASE("a key's error in a car type names the type's line and the first instance, and the expanded text has no anchors", "[trains]") {
  // The copies of a car type share its map keys (train_expansion.cpp, Editor::shared_key): an
  // unknown key still names the type's line and the instance the loader meets first.
  CHECK_THROWS_WITH(testing::model_from_text(replaced(kTrainModel, "unloading_stiffness: 1.0e5", "unloading_stifness: 1.0e5")),
                    Contains("test.yaml:11: element 'unitA.car1.crush' (crush_spring): unknown key 'unloading_stifness'") &&
                        Contains("(car type 'coach', line 6; instance unitA.car1, line 27)"));
  CHECK_THROWS_WITH(testing::model_from_text(replaced(kTrainModel, "{name: nose, mass: 10,", "{name: nose, mas: 10,")),
                    Contains("test.yaml:9: body 'unitA.car1.nose'") && Contains("unknown key 'mas'") &&
                        Contains("(car type 'coach', line 6; instance unitA.car1, line 27)"));
  CHECK_THROWS_WITH(testing::model_from_text(replaced(kTrainModel, "stiffness: 1.0e6", "stifness: 1.0e6")),
                    Contains("test.yaml:20: element 'unitA.coupling1.spring' (linear_spring): unknown key 'stifness'") &&
                        Contains("(interface type 'bar', line 18; coupling unitA.coupling1 (line 25))"));
  // A setting on one instance does not claim the type's shared key for the other instances'
  // messages: car1's unknown key still names the file's line, not car3's setting.
  CHECK_THROWS_WITH(load_model_text(replaced(kTrainModel, "unloading_stiffness: 1.0e5", "unloading_stifness: 1.0e5"), "test.yaml",
                                    {"unitA.car3.crush.unloading_stifness=2.0e5"}),
                    Contains("test.yaml:11: element 'unitA.car1.crush' (crush_spring): unknown key 'unloading_stifness'") &&
                        Contains("(car type 'coach', line 6; instance unitA.car1, line 27)"));
  // An emitter writes a node reached twice as an anchor (&1) and aliases (*1): the expanded
  // text is written from an unshared copy, each key spelled out in each instance.
  const std::string text = expand_model_file(write_temp("railcrash_shared_keys.yaml", kTrainModel), {}).text;
  CHECK(text.find('&') == std::string::npos);
  CHECK(text.find('*') == std::string::npos);
  std::size_t instances = 0;
  for (auto at = text.find("unloading_stiffness: 1.0e5"); at != std::string::npos; at = text.find("unloading_stiffness: 1.0e5", at + 1))
    ++instances;
  CHECK(instances == 3);
}

TEST_CASE("settings address a car type (every instance) or one instance, the type's first", "[trains]") {
  const auto masses = [](const Model& m) {
    std::vector<double> out;
    for (const char* car : {"car1", "mid", "car3"}) out.push_back(body(m, std::string("unitA.") + car + ".body").mass);
    return out;
  };
  const std::string path = "trains.yaml";
  CHECK(masses(load_model_text(kTrainModel, path, {"car_types.coach.bodies.body.mass=2000"}).model) == std::vector<double>{2000, 2000, 2000});
  CHECK(masses(load_model_text(kTrainModel, path, {"unitA.mid.body.mass=3000"}).model) == std::vector<double>{1000, 3000, 1000});
  // The instance's setting given first still applies after the type's.
  CHECK(masses(load_model_text(kTrainModel, path, {"unitA.mid.body.mass=3000", "car_types.coach.bodies.body.mass*=1.5"}).model) ==
        std::vector<double>{1500, 3000, 1500});
  CHECK(masses(load_model_text(kTrainModel, path, {"unitA.car3.body.mass*=2"}).model) == std::vector<double>{1000, 1000, 2000});
  // A type's geometry changes every instance's place.
  const Model longer = load_model_text(kTrainModel, path, {"car_types.coach.interfaces.rear.at=[-5.5, 0]"}).model;
  CHECK(body(longer, "unitA.mid.body").x == Approx(-3.7));  // car1's rear 1 further back
  CHECK(load_model_text(kTrainModel, path, {"trains.unitA.speed=3"}).model.bodies()[0].vx == 3.0);
  // A bad value is named by its setting.
  CHECK_THROWS_WITH(load_model_text(kTrainModel, path, {"car_types.coach.elements.crush.unloading_stiffness=-5"}),
                    Contains("trains.yaml: --set 'car_types.coach.elements.crush.unloading_stiffness=-5': element 'unitA.car1.crush'") &&
                        Contains("must be positive"));
  CHECK_THROWS_WITH(load_model_text(kTrainModel, path, {"car_types.coche.bodies.body.mass=1"}),
                    Contains("the model has no 'coche' in 'car_types' (did you mean 'coach'?)"));
  // Flat models and flat keys are untouched.
  CHECK(load_model_text(kTrainModel, path, {"simulation.t_end=0.2"}).run_spec.simulation.t_end == 0.2);
}

TEST_CASE("a generated body or element is also set as bodies.<name>.<key>, and a misspelt name is named with its nearest", "[trains]") {
  const std::string path = "trains.yaml";
  // bodies.<name>.<key> with the name's dots: the same as the instance's own key.
  CHECK(body(load_model_text(kTrainModel, path, {"bodies.unitA.mid.body.mass=3000"}).model, "unitA.mid.body").mass == 3000.0);
  CHECK(body(load_model_text(kTrainModel, path, {"bodies.unitA.mid.body.mass*=2"}).model, "unitA.mid.body").mass == 2000.0);
  CHECK(body(load_model_text(kTrainModel, path, {"bodies.unitA.mid.body.mass=3000"}).model, "unitA.car1.body").mass == 1000.0);
  CHECK(body(load_model_text(kTrainModel, path, {"bodies.unitA.mid.body.velocity[0]=7"}).model, "unitA.mid.body").vx == 7.0);
  // A misspelt generated name, in either form.
  CHECK_THROWS_WITH(load_model_text(kTrainModel, path, {"bodies.unitA.mid.bodyy.mass=3000"}),
                    Contains("trains.yaml: --set 'bodies.unitA.mid.bodyy.mass=3000': the model has no body named 'unitA.mid.bodyy' "
                             "(did you mean 'unitA.mid.body'?)"));
  CHECK_THROWS_WITH(load_model_text(kTrainModel, path, {"unitA.mid.bodyy.mass=3000"}),
                    Contains("trains.yaml: --set 'unitA.mid.bodyy.mass=3000': the model has no body or element named 'unitA.mid.bodyy' "
                             "(did you mean 'unitA.mid.body'?); a train's car's body or element is set as <train>.<car>.<name>.<key>"));
  CHECK_THROWS_WITH(load_model_text(kTrainModel, path, {"unitA.mid.bodyy.mass*=2"}),
                    Contains("the model has no body or element named 'unitA.mid.bodyy' (did you mean 'unitA.mid.body'?)"));
}

TEST_CASE("mm-t-s-N models equal the same model in SI", "[trains][units]") {
  // The two coaches of the flat-model test in mm, t, s, N.
  const std::string si = replaced(replaced(kTrainModel, "      - {type: coach, reversed: true}\n", ""), "gravity: [0, 0]", "");
  std::string mm = replaced(si, "units: SI", "units: mm-t-s-N");
  mm = replaced(mm, "{name: body, mass: 1000, inertia: 100, position: [0.5, 1.0]}", "{name: body, mass: 1, inertia: 1.0e5, position: [500, 1000]}");
  mm = replaced(mm, "{name: nose, mass: 10, inertia: 1, position: [4.0, 1.0]}", "{name: nose, mass: 0.01, inertia: 1000, position: [4000, 1000]}");
  mm = replaced(mm, "curve: [[0, 0], [0.1, 1000]], unloading_stiffness: 1.0e5, points: [{body: nose}, {body: body, at: [2.5, 0]}]",
                "curve: [[0, 0], [100, 1000]], unloading_stiffness: 100, points: [{body: nose}, {body: body, at: [2500, 0]}]");
  mm = replaced(mm, "points: [{body: body, at: [3.5, 0.0]}, {body: nose}]", "points: [{body: body, at: [3500, 0.0]}, {body: nose}]");
  mm = replaced(mm, "{body: ground, at: [0.5, 1.0]}", "{body: ground, at: [500, 1000]}");
  mm = replaced(mm, "front: {body: nose, at: [0.5, 0]}", "front: {body: nose, at: [500, 0]}");
  mm = replaced(mm, "rear: {body: body, at: [-4.5, 0]}", "rear: {body: body, at: [-4500, 0]}");
  mm = replaced(mm, "stiffness: 1.0e6, points: [{end: 1, at: [-0.1, 0]}, {end: 2, at: [0.1, 0]}]",
                "stiffness: 1000, points: [{end: 1, at: [-100, 0]}, {end: 2, at: [100, 0]}]");
  mm = replaced(mm, "front: 10.0", "front: 10000");
  mm = replaced(mm, "speed: 2.0", "speed: 2000");
  mm = replaced(mm, "gap: 0.2", "gap: 200");
  const std::string load_si = "loads:\n  - {type: force, body: unitA.car1.nose, at: [0.1, 0], value: [[0, [0, 0]], [0.01, [-2.0e3, -100]]]}\n"
                              "  - {type: moment, body: unitA.mid.body, value: 50}\n";
  const std::string load_mm = "loads:\n  - {type: force, body: unitA.car1.nose, at: [100, 0], value: [[0, [0, 0]], [0.01, [-2.0e3, -100]]]}\n"
                              "  - {type: moment, body: unitA.mid.body, value: 5.0e4}\n";
  const LoadedModel a_loaded = testing::loaded_from_text(si + load_si), b_loaded = testing::loaded_from_text(mm + load_mm);
  const Model &a = a_loaded.model, &b = b_loaded.model;
  CHECK(b.units == UnitSystem::SI);
  CHECK(b.file_units == "mm-t-s-N");
  CHECK(b.gravity_y == Approx(-9.80665));
  for (std::size_t i = 0; i < a.bodies().size(); ++i) {
    CHECK(b.bodies()[i].mass == Approx(a.bodies()[i].mass).epsilon(1e-14));
    CHECK(b.bodies()[i].inertia == Approx(a.bodies()[i].inertia).epsilon(1e-14));
    CHECK(b.bodies()[i].x == Approx(a.bodies()[i].x).epsilon(1e-14));
    CHECK(b.bodies()[i].vx == Approx(a.bodies()[i].vx).epsilon(1e-14));
  }
  CHECK(b.loads()[1].value.values[0][0] == Approx(50.0).epsilon(1e-14));  // 5e4 N mm = 50 N m
  const RunOutcome ra = testing::simulate(a_loaded, 0.01), rb = testing::simulate(b_loaded, 0.01);
  REQUIRE(ra.y.size() == rb.y.size());
  for (std::size_t i = 0; i < ra.y.size(); ++i) CHECK(rb.y[i] == Approx(ra.y[i]).epsilon(1e-7).margin(1e-10));
  CHECK(rb.final_energy.kinetic == Approx(ra.final_energy.kinetic).epsilon(1e-7));
}

TEST_CASE("the example models of modern units load and run", "[trains][examples]") {
  for (const char* name : {"emu3_unit_collision.yaml", "emu3_wall.yaml", "emu3_wagon.yaml"}) {
    const std::string path = std::string(RAILCRASH_SOURCE_DIR) + "/models/examples/" + name;
    INFO(path);
    std::ifstream file(path);
    std::size_t lines = 0;
    bool illustrative = false;
    for (std::string line; std::getline(file, line); ++lines) illustrative = illustrative || line.find("ILLUSTRATIVE") != std::string::npos;
    CHECK(lines <= 200);
    CHECK(illustrative);
    const LoadedModel loaded = load_model(path, {"simulation.t_end=0.01"});
    const Model& model = loaded.model;
    CHECK(model.body_count() >= 15);
    std::size_t cars = 0;
    for (const Body& b : model.bodies()) cars += b.name.size() > 5 && b.name.substr(b.name.size() - 5) == ".body";
    CHECK(cars >= 3);
    const RunReport report = run_model(model, loaded.run_spec, "");  // as `railcrash run` (assembly, settling, run)
    INFO(report.outcome.message);
    CHECK(report.outcome.ok);
  }
}

TEST_CASE("two identical units meeting head on stay mirror images of each other", "[trains][examples]") {
  // unitA (facing +x, 10 m/s) and unitB (facing -x, standing) are built from the same car types,
  // unitB's cars mirrored; their fronts start 50 mm apart about x = 25 mm. In the frame of the
  // centre of mass (5 m/s) the two units are mirror images, so every body of unitA and its
  // twin in unitB keep x_A + x_B = 0.05 m + 10 m/s t and y_A = y_B through the crash.
  const std::string path = std::string(RAILCRASH_SOURCE_DIR) + "/models/examples/emu3_unit_collision.yaml";
  const double t_end = 0.12;  // [s] the cab fronts crush from 5 ms on
  const LoadedModel loaded = load_model(path, {"simulation.t_end=0.12"});
  const Model& model = loaded.model;
  const RunReport report = run_model(model, loaded.run_spec, "");
  REQUIRE(report.outcome.ok);
  REQUIRE(report.outcome.t_reached == Approx(t_end));
  const std::vector<double>& y = report.outcome.y;
  std::size_t pairs = 0;
  for (const Body& a : model.bodies()) {
    if (a.name.rfind("unitA.", 0) != 0) continue;
    const auto twin = model.find_body("unitB." + a.name.substr(6));
    REQUIRE(twin);
    const auto i = static_cast<std::size_t>(*model.find_body(a.name)), k = static_cast<std::size_t>(*twin);
    INFO(a.name);
    CHECK(y[3 * i] + y[3 * k] == Approx(0.05 + 10.0 * t_end).margin(1e-3));
    // (the anticlimber measures in body 1's frame, so the pair is mirrored only to its
    // tolerances: the cab front ends' heights differ by 0.13 mm of their 15 mm drop)
    CHECK(y[3 * i + 1] == Approx(y[3 * k + 1]).margin(1e-3));
    ++pairs;
  }
  CHECK(pairs == 15);
  // The fronts did crush: unitA's cab front body moved back along its car by more than 0.1 m.
  const auto body_a = static_cast<std::size_t>(*model.find_body("unitA.car1.body"));
  const auto front_a = static_cast<std::size_t>(*model.find_body("unitA.car1.front_end"));
  CHECK(y[3 * front_a] - y[3 * body_a] < 12.2 - 0.1);
}

TEST_CASE("consist makes a model's trains N cars long, repeating its cars in turn", "[trains][consist]") {
  const std::string text = make_consist_model(YAML::Load(kTrainModel), "three.yaml", 5);
  const Model model = load_model_text(text, "consist.yaml").model;
  REQUIRE(model.body_count() == 10);
  // Cars 1-3 as listed (the third reversed), then car4 = car1 and car5 = the named middle car,
  // each 8.5 long over its ends with 0.2 between: car k's front at 10 - (k - 1) 8.7.
  for (int k = 1; k <= 5; ++k) {
    const bool reversed = k == 3;
    const double front = 10.0 - (k - 1) * 8.7;
    INFO("car " << k);
    // the body's centre lies 4.0 behind the front interface; a reversed car leads with its
    // rear interface, 4.5 behind it in the car's coordinates
    CHECK(body(model, "unitA.car" + std::to_string(k) + ".body").x == Approx(reversed ? front - 4.5 : front - 4.0));
  }
  CHECK_THROWS_WITH(make_consist_model(YAML::Load("railcrash: 1\ntrains: {a: 1}\n"), "bad.yaml", 2),
                    Contains("bad.yaml:2: consist: 'trains' must be a list of trains"));
}

TEST_CASE("train and car names longer than 256 characters are refused with file and line", "[trains]") {
  const std::string long_name(300, 't');
  for (const auto& [from, to] : {std::pair<std::string, std::string>{"- name: unitA", "- name: " + long_name},
                                 {"{type: coach, name: mid}", "{type: coach, name: " + long_name + "}"},
                                 {"  coach:\n", "  " + long_name + ":\n"}}) {
    INFO("edit: " << from);
    const std::string path = write_temp("railcrash_long_name_train.yaml", replaced(kTrainModel, from, to));
    CHECK_THROWS_WITH(load_model(path), Contains("railcrash_long_name_train.yaml:") && Contains("is 300 characters long") &&
                                            Contains("more than the limit of 256"));
  }
}
