#include "railcrash/model/yaml_reader.hpp"

#include <cmath>
#include <optional>

#include "railcrash/model/model_io.hpp"
#include "railcrash/model/yaml_file.hpp"

namespace railcrash {

void YamlReader::fail(const YAML::Node& node, const std::string& message) const { yaml_error(file_, node, message); }

void YamlReader::require_map(const YAML::Node& node, const std::string& what) const {
  if (!node.IsMap()) fail(node, what + " must be a map of keys (key: value)");
}

void YamlReader::require_list(const YAML::Node& node, const std::string& what) const {
  if (!node.IsSequence()) fail(node, what + " must be a list (lines starting with '- ')");
}

void YamlReader::check_keys(const YAML::Node& map, const std::vector<std::string>& allowed, const std::string& context) const {
  if (const auto problem = yaml_keys_problem(map, allowed, context)) fail(problem->where, problem->message);
}

void YamlReader::check_map_keys(const YAML::Node& map, const std::vector<std::string>& allowed, const std::string& context) const {
  require_map(map, context);
  check_keys(map, allowed, context);
}

YAML::Node YamlReader::required(const YAML::Node& map, const std::string& key, const std::string& context) const {
  const YAML::Node node = map[key];
  if (!node) fail(map, context + ": missing required key '" + key + "'");
  return node;
}

double YamlReader::number(const YAML::Node& node, const std::string& what) const {
  if (node.IsNull()) fail(node, what + " must be a number (it is empty)");
  if (!node.IsScalar()) fail(node, what + " must be a number");
  double value = 0.0;
  try {
    value = node.as<double>();
  } catch (const YAML::Exception&) {
    fail(node, what + " must be a number, not '" + node.Scalar() + "'");
  }
  if (!std::isfinite(value)) fail(node, what + " must be a finite number, not '" + node.Scalar() + "'");
  return value;
}

std::optional<double> YamlReader::positive_key(const YAML::Node& map, const std::string& key, const std::string& section) const {
  const YAML::Node node = map[key];
  if (!node) return std::nullopt;
  const double value = number(node, section + ": " + key);
  if (!(value > 0.0)) fail(node, section + ": " + key + " must be positive");
  return value;
}

std::vector<double> YamlReader::numbers(const YAML::Node& node, std::size_t size, const std::string& what) const {
  if (!node.IsSequence() || (size > 0 && node.size() != size)) {
    std::string shape = size == 2 ? "[a, b]" : "a list of numbers";
    fail(node, what + " must be " + (size > 0 ? "a list of " + std::to_string(size) + " numbers " + shape : shape) +
                   (node.IsSequence() ? ", not a list of " + std::to_string(node.size()) : ""));
  }
  std::vector<double> out;
  for (std::size_t i = 0; i < node.size(); ++i) out.push_back(number(node[i], what + " entry " + std::to_string(i + 1)));
  return out;
}

bool YamlReader::boolean(const YAML::Node& node, const std::string& what) const {
  std::optional<bool> value;
  try {
    if (node.IsScalar()) value = node.as<bool>();
  } catch (const YAML::Exception&) {
  }
  if (!value) fail(node, what + " must be true or false");
  return *value;
}

std::string YamlReader::text(const YAML::Node& node, const std::string& what) const {
  if (!node.IsScalar()) fail(node, what + " must be a word");
  return node.Scalar();
}

std::string YamlReader::name(const YAML::Node& node, const std::string& what) const {
  const std::string value = text(node, what);
  if (value.empty()) fail(node, what + " must not be empty");
  if (const std::string problem = name_length_problem(what, value); !problem.empty()) fail(node, problem);
  for (std::size_t i = 0; i < value.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(value[i]);
    if (c < 0x20 || c == 0x7F || std::string(",\"'\\<>&").find(static_cast<char>(c)) != std::string::npos)
      fail(node, what + " '" + printable(value) + "' holds the character " + (c < 0x20 || c == 0x7F ? "code " + std::to_string(c) : "'" + std::string(1, static_cast<char>(c)) + "'") +
                     ", which would break the CSV, JSON and report files; use letters, digits, _ - . and spaces");
    if (c >= 0x80) {
      const std::size_t length = (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
      bool ok = length > 0 && i + length <= value.size();
      for (std::size_t k = 1; ok && k < length; ++k) ok = (static_cast<unsigned char>(value[i + k]) >> 6) == 0x2;
      if (!ok) fail(node, what + " '" + printable(value) + "' is not valid UTF-8 text; save the model file as UTF-8");
      i += length - 1;
    }
  }
  return value;
}

std::string YamlReader::printable(const std::string& value) {
  std::string out;
  for (char c : value) out += (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7F) ? '?' : c;
  return out;
}

}  // namespace railcrash
