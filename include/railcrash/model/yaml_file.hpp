// Reading the studies' own YAML files (design, readings) with input errors that name the file
// and line; a helper for the YAML that generated models are written with.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "railcrash/core/error.hpp"

namespace railcrash {

/// Limits on what a YAML input may expand to: aliases (*name) are counted as the values they
/// stand for, so an alias "billion laughs" or an alias inside its own anchor is refused before
/// anything walks the nodes.
constexpr std::size_t kYamlMaxAliasedNodes = 2000000;  // [values] that aliases may add beyond the text's size
constexpr std::size_t kYamlMaxDepth = 64;              // [levels] of nested lists and maps
constexpr std::size_t kYamlMaxFileBytes = 64u << 20;  // [bytes] of an input file

/// The text of the file at `path` (`what` names it in messages: "model file"). InputError when
/// it cannot be opened, is a folder or a device (/dev/zero would never end), or is larger than
/// kYamlMaxFileBytes.
std::string read_input_file(const std::string& path, const std::string& what);

/// Throws InputError "path:line: ..." if `text` nests deeper than kYamlMaxDepth, expands to more
/// than kYamlMaxAliasedNodes + (its size in bytes) values, or has an alias inside the node it refers to. Parse
/// errors are thrown as YAML::ParserException (with their mark), as YAML::Load does.
void check_yaml_structure(const std::string& text, const std::string& path);

/// check_yaml_structure, then YAML::Load.
YAML::Node load_yaml_text(const std::string& text, const std::string& path);

/// A YAML text that has passed check_yaml_structure, checked when it is made. A sweep builds
/// every run's model from one text: walking its structure again for each run was 1.3 % of a
/// sweep run of the two-car crash (bench/HISTORY.md, "Sweeps").
class CheckedYamlText {
 public:
  /// Checks `text` (InputError or YAML::ParserException as check_yaml_structure).
  CheckedYamlText(std::string text, const std::string& path) : text_(std::move(text)) { check_yaml_structure(text_, path); }
  const std::string& text() const { return text_; }

 private:
  std::string text_;
};

/// YAML::Load of a text already checked.
inline YAML::Node load_yaml_text(const CheckedYamlText& text) { return YAML::Load(text.text()); }

/// Parses the YAML file at `path` (checked as above); `what` names it in the message ("design file").
YAML::Node load_yaml_file(const std::string& path, const std::string& what);

/// The flow-style sequence [a, b] (positions, points and velocities of generated models).
inline YAML::Node flow_pair(double a, double b) {
  YAML::Node n(YAML::NodeType::Sequence);
  n.push_back(a);
  n.push_back(b);
  n.SetStyle(YAML::EmitterStyle::Flow);
  return n;
}

/// " (did you mean 'x'?)" when a word of `known` is close to `word` (edit distance < 3), else "".
std::string suggestion(const std::string& word, const std::vector<std::string>& known);
/// "a, b, c".
std::string join_words(const std::vector<std::string>& words);

/// What is wrong with a key of a YAML map, and the node to name in the message.
struct YamlKeyProblem {
  YAML::Node where;
  std::string message;
};
/// The one check of a map's keys, for every YAML input (model files, car types, scenario
/// sections, plan, design and readings files): each key a plain word, one of `allowed`, and
/// given once. The problem's message: "CONTEXT: unknown key 'k' (did you mean 'x'?); allowed
/// keys: a, b, c", "CONTEXT: key 'k' is given twice; keep only one" or "CONTEXT: keys must be
/// plain words; allowed keys: ...". nullopt when the keys are right.
std::optional<YamlKeyProblem> yaml_keys_problem(const YAML::Node& map, const std::vector<std::string>& allowed,
                                                const std::string& context);
/// yaml_keys_problem for a file read without a model reader: InputError "path:line: ...".
void check_yaml_keys(const std::string& path, const YAML::Node& map, const std::vector<std::string>& allowed,
                     const std::string& context);

/// The 1-based line of a node (0: unknown).
inline int yaml_line(const YAML::Node& node) { return node && !node.Mark().is_null() ? node.Mark().line + 1 : 0; }

/// Throws InputError "path:line: message" at the node.
[[noreturn]] inline void yaml_error(const std::string& path, const YAML::Node& node, const std::string& message) {
  throw InputError(SourceLocation{path, yaml_line(node)}.prefix() + message);
}

}  // namespace railcrash
