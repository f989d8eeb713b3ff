// The one reader class of the YAML inputs: model files (model_io.cpp), car types and trains
// (train_expansion.cpp), consist templates (scenarios/consist.cpp) and scenario sections
// (results/scenario_criteria.cpp). It holds what they share: the file name, a node's line,
// failing with "FILE:LINE: ", and the checks of maps, lists, keys, required keys, numbers,
// lists of numbers, flags, words and names, each worded once. A reader derives from it and
// overrides fail() when its messages start with its section ("consist template: ") or when
// its nodes may come from somewhere else than the file (a --set, a car type's copy).
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "railcrash/core/error.hpp"

namespace railcrash {

class YamlReader {
 public:
  /// `file` names the input in every message ("" for none: messages then start with the line).
  explicit YamlReader(std::string file) : file_(std::move(file)) {}
  virtual ~YamlReader() = default;

  const std::string& file() const { return file_; }

  /// Throws InputError "FILE:LINE: message" at `node` (its line from 1; none for a node with
  /// no place in the text).
  [[noreturn]] virtual void fail(const YAML::Node& node, const std::string& message) const;

  /// "WHAT must be a map of keys (key: value)" unless `node` is a map.
  void require_map(const YAML::Node& node, const std::string& what) const;
  /// "WHAT must be a list (lines starting with '- ')" unless `node` is a list.
  void require_list(const YAML::Node& node, const std::string& what) const;
  /// Rejects keys outside `allowed` (naming the closest allowed one) and repeated keys
  /// (yaml_keys_problem's messages, yaml_file.hpp).
  void check_keys(const YAML::Node& map, const std::vector<std::string>& allowed, const std::string& context) const;
  /// require_map(map, context), then check_keys.
  void check_map_keys(const YAML::Node& map, const std::vector<std::string>& allowed, const std::string& context) const;
  /// map[key]; "CONTEXT: missing required key 'KEY'" (at the map) when it is not given.
  YAML::Node required(const YAML::Node& map, const std::string& key, const std::string& context) const;

  /// A finite number: "WHAT must be a number (it is empty)", "... must be a number", "... must be a
  /// number, not 'x'", "... must be a finite number, not '.nan'".
  double number(const YAML::Node& node, const std::string& what) const;
  /// map[key] as a positive number, nullopt when not given: "SECTION: KEY must be positive".
  std::optional<double> positive_key(const YAML::Node& map, const std::string& key, const std::string& section) const;
  /// A list of numbers, of `size` entries when size > 0 ("WHAT must be a list of 2 numbers [a, b],
  /// not a list of 3"); its entries read as number(entry, "WHAT entry K").
  std::vector<double> numbers(const YAML::Node& node, std::size_t size, const std::string& what) const;
  /// true or false: "WHAT must be true or false".
  bool boolean(const YAML::Node& node, const std::string& what) const;
  /// A scalar's text (may be empty): "WHAT must be a word".
  std::string text(const YAML::Node& node, const std::string& what) const;
  /// A body or element name: it becomes CSV column headers, JSON keys and report text, so it may
  /// not be empty, nor longer than kMaxNameLength (model_io.hpp), nor hold a comma, quote,
  /// backslash, <, >, &, a control character or invalid UTF-8.
  std::string name(const YAML::Node& node, const std::string& what) const;

  /// `value` with every character outside printable ASCII shown as '?'.
  static std::string printable(const std::string& value);

 private:
  std::string file_;
};

}  // namespace railcrash
