// The element declarations are the one source of truth for element keys: every factory
// reads exactly the keys its type declares, the loader's messages (missing key, range,
// unknown key) come from the declarations.
#include <catch2/catch.hpp>
#include <yaml-cpp/yaml.h>

#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "railcrash/model/element_registry.hpp"
#include "support.hpp"

using namespace railcrash;

namespace {

/// An element's parameters as "key: value" lines, in order.
using Parameters = std::vector<std::pair<std::string, std::string>>;

Parameters example_parameters(const ElementType& type) {
  Parameters out;
  const YAML::Node example = YAML::Load(type.example);
  REQUIRE(example.IsMap());
  for (const auto& entry : example) out.emplace_back(entry.first.Scalar(), YAML::Dump(entry.second));
  return out;
}

/// Sets (or adds) `key`.
Parameters with(Parameters parameters, const std::string& key, const std::string& value) {
  for (auto& entry : parameters)
    if (entry.first == key) {
      entry.second = value;
      return parameters;
    }
  parameters.emplace_back(key, value);
  return parameters;
}

Parameters without(Parameters parameters, const std::string& key) {
  Parameters out;
  for (auto& entry : parameters)
    if (entry.first != key) out.push_back(entry);
  return out;
}

/// A two-body SI model with one element `e` of `type` (its declared number of points).
std::string model_text(const ElementType& type, const Parameters& parameters) {
  std::string text =
      "railcrash: 1\nname: registry\nunits: SI\ngravity: [0, 0]\nbodies:\n"
      "  - {name: car1, mass: 1, inertia: 1, position: [0, 0]}\n"
      "  - {name: car2, mass: 1, inertia: 1, position: [1, 0]}\n"
      "elements:\n  - name: e\n    type: " + type.name + "\n    points: [{body: car1, at: [0, 0]}" +
      (type.points > 1 ? ", {body: car2, at: [0, 0]}" : "") + "]\n";
  for (const auto& entry : parameters) text += "    " + entry.first + ": " + entry.second + "\n";
  return text + "simulation: {t_end: 1}\n";
}

/// The message of the InputError loading `text` throws ("" when it loads).
std::string load_error(const std::string& text) {
  try {
    (void)testing::model_from_text(text);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

/// "test.yaml:N: " for the line that starts with `    key:`.
std::string location_of(const std::string& text, const std::string& key) {
  const std::size_t at = text.find("\n    " + key + ":");
  REQUIRE(at != std::string::npos);
  const auto line = 2 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n');
  return "test.yaml:" + std::to_string(line) + ": ";
}

/// Serves an element's parameters from a YAML map and records every key the factory asks for.
class RecordingReader : public ParameterReader {
 public:
  RecordingReader(const ElementType& type, YAML::Node parameters, UnitSystem units = UnitSystem::SI)
      : ParameterReader(type, units), parameters_(parameters) {}
  std::set<std::string> asked;

  [[noreturn]] void fail(const std::string& key, const std::string& what_to_change) const override {
    throw InputError("'" + key + "': " + what_to_change);
  }

 protected:
  std::optional<double> given_number(const std::string& key) override {
    asked.insert(key);
    return parameters_[key] ? std::optional<double>(parameters_[key].as<double>()) : std::nullopt;
  }
  std::optional<std::vector<double>> given_vector(const std::string& key, std::size_t) override {
    asked.insert(key);
    return parameters_[key] ? std::optional<std::vector<double>>(parameters_[key].as<std::vector<double>>()) : std::nullopt;
  }
  std::optional<std::vector<std::vector<double>>> given_table(const std::string& key, std::size_t) override {
    asked.insert(key);
    if (!parameters_[key]) return std::nullopt;
    return parameters_[key].as<std::vector<std::vector<double>>>();
  }
  std::optional<bool> given_flag(const std::string& key) override {
    asked.insert(key);
    return parameters_[key] ? std::optional<bool>(parameters_[key].as<bool>()) : std::nullopt;
  }
  std::optional<std::string> given_word(const std::string& key) override {
    asked.insert(key);
    return parameters_[key] ? std::optional<std::string>(parameters_[key].Scalar()) : std::nullopt;
  }

 private:
  YAML::Node parameters_;
};

/// " (force/length [N/m]: spring rate)": how messages describe a key of an SI model.
std::string described(const ParameterSpec& spec) {
  const std::string symbol = unit_symbol(spec.unit, UnitSystem::SI);
  return " (" + std::string(unit_kind_name(spec.unit)) + (symbol.empty() ? "" : " [" + symbol + "]") + ": " +
         spec.meaning + ")";
}

/// A value `range` rejects, written for `shape`.
std::string out_of_range_value(const ParameterSpec& spec) {
  const std::string number = spec.range == Range::Positive      ? "0"
                             : spec.range == Range::NonNegative ? "-1"
                                                                : "1.5";  // Fraction, UnitInterval
  if (spec.shape == Shape::Pair) return "[" + number + ", " + number + "]";
  if (spec.shape == Shape::Table) return "[[0, 0], [1, " + number + "]]";
  return number;
}

std::string range_message(const ParameterSpec& spec) {
  switch (spec.range) {
    case Range::Positive: return "'" + spec.name + "' must be positive, not 0";
    case Range::NonNegative: return "'" + spec.name + "' must not be negative, not -1";
    case Range::Fraction: return "'" + spec.name + "' must be above 0 and at most 1, not 1.5";
    case Range::UnitInterval: return "'" + spec.name + "' must be between 0 and 1, not 1.5";
    case Range::Any: break;
  }
  return "";
}

/// `key` with its second character doubled: one edit away from it (and further from its
/// neighbours: "unloading_curve" -> "unnloading_curve", not "uloading_curve", which is as
/// close to loading_curve).
std::string misspelt(const std::string& key) { return key.substr(0, 2) + key.substr(1); }

}  // namespace

TEST_CASE("every element type's example loads, and its factory reads exactly the keys the type declares", "[registry]") {
  const ElementRegistry& registry = ElementRegistry::instance();
  REQUIRE(registry.types().size() == 21);
  for (const std::string& name : registry.types()) {
    INFO("element type " << name);
    const ElementType& type = *registry.find(name);
    CHECK(!type.summary.empty());
    CHECK(!type.points_meaning.empty());
    for (const ParameterSpec& spec : type.parameters) CHECK(!spec.meaning.empty());
    // Loads as a model element (a key the factory reads undeclared would throw std::logic_error).
    const Model model = testing::model_from_text(model_text(type, example_parameters(type)));
    REQUIRE(model.elements().size() == 1);
    CHECK(model.elements()[0]->type() == name);
    // Run directly: the keys the factory asks for are the declared ones, all of them (a
    // declared key no factory reads would be accepted and silently ignored).
    RecordingReader reader(type, YAML::Load(type.example));
    ElementSpec spec;
    spec.name = "e";
    spec.type = name;
    spec.points.assign(type.points, PointRef{});
    for (std::size_t k = 0; k < spec.points.size(); ++k) spec.points[k].body = static_cast<int>(k);
    spec.parameters = &reader;
    REQUIRE(type.factory(spec) != nullptr);
    const std::vector<std::string> declared = type.keys();
    CHECK(reader.asked == std::set<std::string>(declared.begin(), declared.end()));
  }
}

TEST_CASE("every required key, left out, is reported missing by name with its unit kind and meaning", "[registry]") {
  const ElementRegistry& registry = ElementRegistry::instance();
  int checked = 0;
  for (const std::string& name : registry.types()) {
    const ElementType& type = *registry.find(name);
    const Parameters example = example_parameters(type);
    for (const ParameterSpec& spec : type.parameters) {
      if (spec.presence.kind != Presence::Required) continue;
      INFO("element type " << name << ", key " << spec.name);
      const std::string message = load_error(model_text(type, without(example, spec.name)));
      CHECK_THAT(message, Catch::Contains("test.yaml:9: element 'e' (" + name + "): missing required parameter '" +
                                          spec.name + "'" + described(spec)));
      ++checked;
    }
  }
  CHECK(checked >= 40);  // e.g. the anticlimber's nine, the beams' material
}

TEST_CASE("a value outside a key's declared range gives the range message at the key's line", "[registry]") {
  const ElementRegistry& registry = ElementRegistry::instance();
  int checked = 0;
  for (const std::string& name : registry.types()) {
    const ElementType& type = *registry.find(name);
    const Parameters example = example_parameters(type);
    for (const ParameterSpec& spec : type.parameters) {
      if (spec.range == Range::Any) continue;
      INFO("element type " << name << ", key " << spec.name);
      const std::string text = model_text(type, with(example, spec.name, out_of_range_value(spec)));
      CHECK_THAT(load_error(text), Catch::Contains(location_of(text, spec.name) + "element 'e' (" + name + "): " +
                                                   range_message(spec) + described(spec)));
      ++checked;
    }
  }
  CHECK(checked >= 80);
}

TEST_CASE("a misspelt key is rejected with the declared key it is closest to", "[registry]") {
  const ElementRegistry& registry = ElementRegistry::instance();
  for (const std::string& name : registry.types()) {
    const ElementType& type = *registry.find(name);
    const Parameters example = example_parameters(type);
    for (const ParameterSpec& spec : type.parameters) {
      INFO("element type " << name << ", key " << spec.name);
      const std::string typo = misspelt(spec.name);
      const std::string text = model_text(type, with(without(example, spec.name), typo, "1"));
      CHECK_THAT(load_error(text), Catch::Contains(location_of(text, typo) + "element 'e' (" + name + "): unknown key '" +
                                                   typo + "' (did you mean '" + spec.name + "'?)"));
    }
  }
}

TEST_CASE("a wrong number of points is refused with the declared count and what the points are", "[registry]") {
  for (const std::string& name : ElementRegistry::instance().types()) {
    INFO("element type " << name);
    const ElementType& type = *ElementRegistry::instance().find(name);
    std::string text = model_text(type, example_parameters(type));
    const std::string one_more = type.points == 1 ? ", {body: car2, at: [0, 0]}]" : ", {body: car2, at: [1, 0]}]";
    text.replace(text.find("]\n    ", text.find("points:")), 1, one_more);
    CHECK_THAT(load_error(text), Catch::Contains("test.yaml:9: element 'e' (" + name + ") needs exactly " +
                                                 std::to_string(type.points) + (type.points == 1 ? " point" : " points") +
                                                 ", found " + std::to_string(type.points + 1) + " (" +
                                                 type.points_meaning + ")"));
  }
}

TEST_CASE("messages name a key's unit in the model's unit system", "[registry]") {
  const std::string in_lbf_s =
      "railcrash: 1\nname: t\nunits: in-lbf-s\nbodies:\n  - {name: a, weight: 100, inertia: 1, position: [0, 0]}\n"
      "elements:\n  - name: k\n    type: linear_spring\n    points: [{body: ground}, {body: a}]\n    stiffness: -3\n"
      "simulation: {t_end: 1}\n";
  CHECK_THAT(load_error(in_lbf_s), Catch::Contains("test.yaml:10: element 'k' (linear_spring): 'stiffness' must not be "
                                                   "negative, not -3 (force/length [lbf/in]: spring rate)"));
  std::string si = in_lbf_s;
  si.replace(si.find("in-lbf-s"), 8, "SI");
  si.replace(si.find("weight: 100"), 11, "mass: 1");
  si.replace(si.find("    stiffness: -3\n"), 18, "");
  CHECK_THAT(load_error(si), Catch::Contains("test.yaml:7: element 'k' (linear_spring): missing required parameter "
                                             "'stiffness' (force/length [N/m]: spring rate)"));
}

TEST_CASE("the reader refuses undeclared keys and wrong shapes, and hands out declared defaults", "[registry]") {
  const ElementType& spring = *ElementRegistry::instance().find("linear_spring");
  const ElementType& pin = *ElementRegistry::instance().find("pin_joint");
  const ElementType& anticlimber = *ElementRegistry::instance().find("anticlimber");
  RecordingReader empty_spring(spring, YAML::Load("{}"));
  CHECK_THROWS_AS(empty_spring.number("stifness"), std::logic_error);
  CHECK_THROWS_AS(empty_spring.vector("stiffness", 2), std::logic_error);
  CHECK_THROWS_AS(empty_spring.value("free_length"), std::logic_error);  // optional without a default
  CHECK(empty_spring.number("free_length") == std::nullopt);
  CHECK_THROWS_WITH(empty_spring.value("stiffness"), Catch::Contains("missing required parameter 'stiffness'"));
  RecordingReader empty_pin(pin, YAML::Load("{}"));
  CHECK(empty_pin.value("friction_velocity") == 0.01);  // declared default
  CHECK(empty_pin.value("friction_radius") == 0.0);
  RecordingReader empty_anticlimber(anticlimber, YAML::Load("{}"));
  CHECK(empty_anticlimber.word("interlock_while_unloading") == std::string("hold"));
  RecordingReader given_pin(pin, YAML::Load("{friction_velocity: 0.5}"));
  CHECK(given_pin.value("friction_velocity") == 0.5);
}

TEST_CASE("a dimensional default is one physical value in every unit system", "[registry][units]") {
  // friction_velocity's 0.01 once applied in the model's own units: 0.01 in/s in an in-lbf-s
  // model, 0.01 m/s (39 times faster) in SI, so the same model regularized its friction
  // differently when written in SI. Every default with a unit is now zero, an angle (rad in
  // both) or given per unit system.
  int per_unit_system = 0;
  for (const std::string& name : ElementRegistry::instance().types()) {
    const ElementType& type = *ElementRegistry::instance().find(name);
    for (const ParameterSpec& spec : type.parameters) {
      INFO(name << "." << spec.name);
      if (spec.presence.kind != Presence::Default || spec.shape != Shape::Number) continue;
      const bool same_in_both = spec.unit == Unit::Dimensionless || spec.unit == Unit::Angle ||
                                spec.unit == Unit::AngularVelocity || spec.unit == Unit::Choice;
      if (same_in_both || spec.presence.value == 0.0) {
        CHECK(!spec.presence.si_value);
        continue;
      }
      REQUIRE(spec.presence.si_value);
      REQUIRE(spec.unit == Unit::Velocity);  // the only kind with a per-unit default so far
      CHECK(*spec.presence.si_value == Approx(spec.presence.value * metres_per_length_unit(UnitSystem::InLbfS)).epsilon(1e-15));
      RecordingReader in_inches(type, YAML::Load("{}"), UnitSystem::InLbfS), in_si(type, YAML::Load("{}"), UnitSystem::SI);
      CHECK(in_inches.value(spec.name) == 0.01);  // the in-lbf-s models' value, the report's reading
      CHECK(in_si.value(spec.name) == Approx(2.54e-4).epsilon(1e-15));
      ++per_unit_system;
    }
  }
  CHECK(per_unit_system == 5);  // friction_velocity of contact, wheel_rail, coupler_end, coupling, slider_joint
}

TEST_CASE("a friction element left at its default slip speed regularizes alike in SI, mm-t-s-N and in-lbf-s", "[registry][units]") {
  // The same block on the same slider, written three ways: the element's slip speed, in m/s,
  // must not depend on the units the file was written in.
  const auto slip_speed_in_metres_per_second = [](const std::string& units, double length) {
    std::ostringstream s;
    s.precision(17);
    s << "railcrash: 1\nname: slide\nunits: " << units << "\ngravity: [0, 0]\nbodies:\n"
      << "  - {name: block, mass: 1, inertia: 1, position: [0, 0]}\n"
      << "elements:\n  - {name: guide, type: slider_joint, axis: [1, 0], friction: 0.3, slider_length: " << 0.5 * length
      << ", points: [{body: ground, at: [0, 0]}, {body: block, at: [0, 0]}]}\n"
      << "simulation: {t_end: 0.1}\n";
    const Model model = testing::model_from_text(s.str());
    return model.elements()[0]->friction_slip_velocity() * metres_per_length_unit(model.units);
  };
  const double si = slip_speed_in_metres_per_second("SI", 1.0);
  CHECK(si == Approx(2.54e-4).epsilon(1e-12));
  CHECK(slip_speed_in_metres_per_second("mm-t-s-N", 1e3) == Approx(si).epsilon(1e-12));
  CHECK(slip_speed_in_metres_per_second("in-lbf-s", 1.0 / 0.0254) == Approx(si).epsilon(1e-12));
}
