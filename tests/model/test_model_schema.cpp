// The model file's JSON Schema is generated from the loader's key lists and the element
// declarations: every type, parameter and section key appears, and a choice's allowed values are
// read from its declared meaning. (tests/schema/test_model_schema.py validates the models with it.)
#include <catch2/catch.hpp>

#include <algorithm>
#include <string>

#include "railcrash/model/model_io.hpp"
#include "railcrash/model/model_schema.hpp"
#include "railcrash/model/train_expansion.hpp"

using namespace railcrash;

namespace {

ParameterSpec choice(const std::string& meaning, Shape shape = Shape::Number) {
  return {"kind", Unit::Choice, required, Range::Any, meaning, shape};
}

}  // namespace

TEST_CASE("a choice's values are the words before ': ' that start its meaning or follow a comma or semicolon", "[schema]") {
  CHECK(choice_values(choice("1: acts in compression, 2: acts in tension")) == std::vector<std::string>{"1", "2"});
  CHECK(choice_values(choice("1: body 1's face looks along its +x axis, -1: along -x")) == std::vector<std::string>{"1", "-1"});
  CHECK(choice_values(choice("hold: keeps it, as before; release: lets go", Shape::Word)) ==
        std::vector<std::string>{"hold", "release"});
  CHECK(choice_values(choice("true: inside", Shape::Flag)).empty());  // a flag is true or false
  ParameterSpec length{"gap", Unit::Length, required, Range::Any, "kind 1: a length, 2: another", Shape::Number};
  CHECK(choice_values(length).empty());  // not a choice
}

TEST_CASE("every declared choice lists at least two values and its default is one of them", "[schema]") {
  const ElementRegistry& registry = ElementRegistry::instance();
  int choices = 0;
  for (const std::string& name : registry.types())
    for (const ParameterSpec& spec : registry.find(name)->parameters) {
      if (spec.unit != Unit::Choice || spec.shape == Shape::Flag) continue;
      INFO(name << "." << spec.name << ": " << spec.meaning);
      const std::vector<std::string> values = choice_values(spec);
      CHECK(values.size() >= 2);
      if (spec.presence.kind == Presence::Default)
        CHECK(std::find(values.begin(), values.end(), spec.presence.text) != values.end());
      ++choices;
    }
  CHECK(choices >= 3);  // coupling and nonlinear kinds, the anticlimber's facing and interlock
}

TEST_CASE("the model schema has every element type with its declared parameters and every section key", "[schema]") {
  const ElementRegistry& registry = ElementRegistry::instance();
  const std::string schema = model_schema_json(registry);
  REQUIRE(!schema.empty());
  CHECK(schema.front() == '{');
  CHECK(schema.substr(schema.size() - 2) == "}\n");
  CHECK(std::count(schema.begin(), schema.end(), '{') == std::count(schema.begin(), schema.end(), '}'));
  CHECK(std::count(schema.begin(), schema.end(), '[') == std::count(schema.begin(), schema.end(), ']'));
  for (const std::string& name : registry.types()) {
    INFO("element type " << name);
    const std::size_t at = schema.find("\"element_" + name + "\": {");
    REQUIRE(at != std::string::npos);
    const std::size_t end = schema.find("\"additionalProperties\": false", at);  // the end of its definition
    REQUIRE(end != std::string::npos);
    const std::string definition = schema.substr(at, end - at);
    CHECK_THAT(definition, Catch::Contains("\"const\": \"" + name + "\""));
    for (const ParameterSpec& spec : registry.find(name)->parameters) {
      INFO("parameter " << spec.name);
      CHECK_THAT(definition, Catch::Contains("\"" + spec.name + "\": {"));
      CHECK_THAT(definition, Catch::Contains(spec.meaning.substr(0, 40)));
      if (spec.unit != Unit::Choice && spec.unit != Unit::Dimensionless && spec.unit != Unit::Direction)
        CHECK_THAT(definition, Catch::Contains(std::string(unit_symbol(spec.unit, UnitSystem::SI))));
    }
  }
  auto sections = model_file_sections();
  for (const auto& section : train_expansion_sections()) sections.push_back(section);
  for (const auto& section : sections)
    for (const std::string& key : section.second) {
      INFO("section " << section.first << " key " << key);
      CHECK_THAT(schema, Catch::Contains("\"" + key + "\": {"));
    }
}
