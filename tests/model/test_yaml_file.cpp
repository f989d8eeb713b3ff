// The YAML structure check every reader goes through: aliases counted as what they expand
// to, an alias inside its own anchor, and nesting depth, each refused with file and line.
#include <catch2/catch.hpp>

#include <string>
#include <vector>

#include "railcrash/model/model_io.hpp"
#include "railcrash/model/yaml_file.hpp"
#include "railcrash/model/yaml_reader.hpp"

using namespace railcrash;
using Catch::Matchers::Contains;
using Catch::Matchers::StartsWith;

namespace {

/// The message of the InputError read() throws ("" when it throws none).
template <class Read>
std::string input_error(const Read& read) {
  try {
    read();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::string structure_error(const std::string& text) {
  return input_error([&] { check_yaml_structure(text, "in.yaml"); });
}

/// A document whose list `level<k>` repeats `level<k-1>` `fan_out` times: it expands to
/// fan_out^levels + ... values although it is only a few lines long.
std::string alias_tree(int levels, int fan_out) {
  std::string text = "top:\n  level0: &l0 x\n";
  for (int k = 1; k <= levels; ++k) {
    text += "  level" + std::to_string(k) + ": &l" + std::to_string(k) + " [";
    for (int i = 0; i < fan_out; ++i) text += std::string(i ? ", " : "") + "*l" + std::to_string(k - 1);
    text += "]\n";
  }
  return text;
}

}  // namespace

TEST_CASE("aliases are counted as the values they stand for, each node read once", "[yaml_file]") {
  // level k expands to 1 + 3 * size(k - 1) values (1, 4, 13, 40): far below the limit.
  CHECK(structure_error(alias_tree(3, 3)).empty());
  const YAML::Node loaded = load_yaml_text(alias_tree(3, 3), "in.yaml");
  CHECK(loaded["top"]["level3"][2][1][0].as<std::string>() == "x");
  // 10 levels of 10 aliases: 10^10 values from 300 bytes ("billion laughs").
  const std::string laughs = alias_tree(10, 10);
  const std::string message = structure_error(laughs);
  CHECK_THAT(message, StartsWith("in.yaml:"));
  CHECK_THAT(message, Contains("expands to more than " + std::to_string(kYamlMaxAliasedNodes + laughs.size()) + " values"));
}

TEST_CASE("an alias inside the node it refers to is refused with its line", "[yaml_file]") {
  CHECK_THAT(structure_error("name: x\ndescription: &r [*r]\n"),
             StartsWith("in.yaml:2: an alias refers to the node that contains it"));
  CHECK_THAT(structure_error("a: &m\n  b: [1, {c: *m}]\n"), StartsWith("in.yaml:2: an alias refers to the node"));
  // The same anchor used after it is closed is fine.
  CHECK(structure_error("a: &m {b: 1}\nc: *m\n").empty());
}

TEST_CASE("nesting deeper than the limit is refused with its line", "[yaml_file]") {
  const std::size_t depth = kYamlMaxDepth;
  CHECK(structure_error("a: " + std::string(depth - 1, '[') + std::string(depth - 1, ']') + "\n").empty());
  CHECK_THAT(structure_error("a: 1\nb: " + std::string(depth, '[') + std::string(depth, ']') + "\n"),
             StartsWith("in.yaml:2: lists and maps are nested more than 64 deep"));
}

TEST_CASE("the model loader and --set values go through the structure check", "[yaml_file]") {
  const std::string model = "railcrash: 1\nname: x\nunits: SI\ndescription: &r [*r]\nbodies: []\n";
  try {
    (void)load_model_text(model, "model.yaml");
    FAIL("accepted");
  } catch (const InputError& e) {
    CHECK_THAT(std::string(e.what()), StartsWith("model.yaml:4: an alias refers to the node that contains it"));
  }
  const std::string valid = "railcrash: 1\nname: x\nunits: SI\nbodies:\n  - {name: bob, mass: 1, inertia: 1}\n"
                            "simulation: {t_end: 1}\n";
  try {
    (void)load_model_text(valid, "model.yaml", {"description=&a [*a]"});
    FAIL("accepted");
  } catch (const InputError& e) {
    CHECK_THAT(std::string(e.what()), StartsWith("model.yaml: --set 'description=&a [*a]'"));
    CHECK_THAT(std::string(e.what()), Contains("an alias refers to the node that contains it"));
  }
}

TEST_CASE("input files that are folders or devices are refused before they are read", "[yaml_file]") {
  // /dev/zero never ends: reading it as a model (or as a variant's base) took all memory.
  CHECK_THROWS_WITH(read_input_file("/dev/zero", "model file"),
                    StartsWith("/dev/zero: the model file is a device or socket, not a file"));
  CHECK_THROWS_WITH(load_model("/dev/zero"), StartsWith("/dev/zero: the model file is a device"));
  CHECK_THROWS_WITH(read_input_file("/", "design file"), StartsWith("/: the design file is a folder, not a file"));
  CHECK_THROWS_WITH(load_model_text("railcrash: 1\nvariant_of: /dev/zero\n", "variant.yaml"),
                    StartsWith("variant.yaml:2: model variant: variant_of") && Contains("/dev/zero: the base model is a device"));
  CHECK_THROWS_WITH(read_input_file("/no/such/file.yaml", "model file"), Contains("cannot open the model file"));
}

TEST_CASE("a ',' at the start of a document is refused at once, not parsed without end", "[yaml_file]") {
  // yaml-cpp 0.7 answers ",x" with empty values at the same place, without end (found by the fuzzer).
  CHECK_THAT(structure_error(",l"), StartsWith("in.yaml:1: not valid YAML: the parser makes no progress here"));
  CHECK_THAT(structure_error("\n\n,"), StartsWith("in.yaml:3: not valid YAML"));
  CHECK(structure_error("a:\nb:\nc: [, ]\n").find("no progress") == std::string::npos);
}

TEST_CASE("a model text checked once (a sweep's runs) is refused and read exactly as load_model_text", "[yaml_file]") {
  const auto error_of = [](const auto& load) { return input_error(load); };
  // Each refusal says what load_model_text says for the same text: an alias in its own
  // anchor, nesting past the limit, a bracket left open (the bracket's own line), bad YAML.
  for (const std::string& text :
       {std::string("railcrash: 1\nname: x\nunits: SI\ndescription: &r [*r]\nbodies: []\n"),
        "railcrash: 1\nname: " + std::string(kYamlMaxDepth, '[') + std::string(kYamlMaxDepth, ']') + "\n",
        std::string("railcrash: 1\nbodies: [\n  {name: a, mass: 1}\nsimulation: {t_end: 1}\n"),
        std::string("railcrash: 1\n  name: x\n bad")}) {
    const std::string expected = error_of([&] { (void)load_model_text(text, "model.yaml"); });
    REQUIRE_FALSE(expected.empty());
    CHECK(error_of([&] { (void)check_model_text(text, "model.yaml"); }) == expected);
  }
  // A valid text: the same model, with and without --set settings; a setting's own mistakes
  // are still checked (they are not part of the checked text).
  const std::string valid = "railcrash: 1\nname: x\nunits: SI\nbodies:\n  - {name: bob, mass: 1, inertia: 1, position: [0, 0]}\n"
                            "simulation: {t_end: 1}\n";
  const CheckedYamlText checked = check_model_text(valid, "model.yaml");
  CHECK(checked.text() == valid);
  for (const std::vector<std::string>& settings : {std::vector<std::string>{}, std::vector<std::string>{"bodies.bob.mass=2.5"}}) {
    const LoadedModel direct_loaded = load_model_text(valid, "model.yaml", settings);
    const Model& direct = direct_loaded.model;
    const LoadedModel from_checked_loaded = load_model_text(checked, "model.yaml", settings);
    const Model& from_checked = from_checked_loaded.model;
    CHECK(from_checked.bodies()[0].mass == direct.bodies()[0].mass);
    CHECK(from_checked_loaded.run_spec.simulation.t_end == direct_loaded.run_spec.simulation.t_end);
  }
  CHECK(load_model_text(checked, "model.yaml", {"bodies.bob.mass=2.5"}).model.bodies()[0].mass == 2.5);
  CHECK_THAT(error_of([&] { (void)load_model_text(checked, "model.yaml", {"description=&a [*a]"}); }),
             StartsWith("model.yaml: --set 'description=&a [*a]'") && Contains("an alias refers to the node that contains it"));
}

TEST_CASE("one check of a YAML map's keys: unknown (with the closest key and the list), repeated, not a word", "[yaml_file]") {
  const std::vector<std::string> allowed{"limit", "source", "bodies"};
  CHECK_FALSE(yaml_keys_problem(YAML::Load("{limit: 1, source: EN, bodies: [a]}"), allowed, "section"));
  const YAML::Node typo = YAML::Load("limit: 1\nsourse: EN\n");
  const auto unknown = yaml_keys_problem(typo, allowed, "mean_deceleration");
  REQUIRE(unknown);
  CHECK(unknown->message == "mean_deceleration: unknown key 'sourse' (did you mean 'source'?); allowed keys: limit, source, bodies");
  CHECK(yaml_line(unknown->where) == 2);
  const auto twice = yaml_keys_problem(YAML::Load("limit: 1\nsource: EN\nlimit: 2\n"), allowed, "override");
  REQUIRE(twice);
  CHECK(twice->message == "override: key 'limit' is given twice; keep only one");
  CHECK(yaml_line(twice->where) == 3);
  const auto not_a_word = yaml_keys_problem(YAML::Load("? [a, b]\n: 1\n"), allowed, "plan");
  REQUIRE(not_a_word);
  CHECK(not_a_word->message == "plan: keys must be plain words; allowed keys: limit, source, bodies");
  CHECK_THROWS_WITH(check_yaml_keys("plan.yaml", typo, allowed, "plan"),
                    "plan.yaml:2: plan: unknown key 'sourse' (did you mean 'source'?); allowed keys: limit, source, bodies");
}

TEST_CASE("the one YAML reader: file and line on every message, each check worded once", "[yaml_file]") {
  const YAML::Node root = YAML::Load("a: 1.5\nb: x\nc: [1, 2, 3]\nd:\ne: .nan\nf: yes\ng: 'co,mma'\nh: -2\n");
  const YamlReader r("in.yaml");
  const auto message = [](const auto& read) { return input_error(read); };
  CHECK(r.number(root["a"], "a") == 1.5);
  CHECK(message([&] { r.number(root["b"], "b"); }) == "in.yaml:2: b must be a number, not 'x'");
  CHECK(message([&] { r.number(root["c"], "c"); }) == "in.yaml:3: c must be a number");
  CHECK(message([&] { r.number(root["e"], "e"); }) == "in.yaml:5: e must be a finite number, not '.nan'");
  CHECK(message([&] { r.numbers(root["c"], 2, "c"); }) == "in.yaml:3: c must be a list of 2 numbers [a, b], not a list of 3");
  CHECK(r.numbers(root["c"], 0, "c") == std::vector<double>{1.0, 2.0, 3.0});
  CHECK(r.boolean(root["f"], "f"));
  CHECK(message([&] { r.boolean(root["b"], "b"); }) == "in.yaml:2: b must be true or false");
  CHECK(message([&] { r.required(root, "z", "the section"); }) == "in.yaml:1: the section: missing required key 'z'");
  CHECK(message([&] { r.require_map(root["c"], "c"); }) == "in.yaml:3: c must be a map of keys (key: value)");
  CHECK(message([&] { r.require_list(root["a"], "a"); }) == "in.yaml:1: a must be a list (lines starting with '- ')");
  CHECK_THAT(message([&] { r.check_map_keys(root, {"a", "b", "c", "d", "e", "f", "g"}, "top"); }),
             StartsWith("in.yaml:8: top: unknown key 'h'"));
  CHECK(message([&] { r.name(root["g"], "body name"); }).find("in.yaml:7: body name 'co,mma' holds the character ','") == 0);
  CHECK(r.positive_key(root, "a", "simulation") == 1.5);
  CHECK_FALSE(r.positive_key(root, "z", "simulation"));
  CHECK(message([&] { r.positive_key(root, "h", "simulation"); }) == "in.yaml:8: simulation: h must be positive");
}
