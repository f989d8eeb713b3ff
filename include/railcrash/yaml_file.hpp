// Reading the studies' own YAML files (design, readings) with input errors that name the file
// and line; a helper for the YAML that generated models are written with.
#pragma once

#include <yaml-cpp/yaml.h>

#include <string>

#include "railcrash/error.hpp"

namespace railcrash {

/// Parses the YAML file at `path`; `what` names it in the message ("design file").
inline YAML::Node load_yaml_file(const std::string& path, const std::string& what) {
  try {
    return YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw InputError(path + ": cannot open the " + what + " (check the path)");
  } catch (const YAML::ParserException& e) {
    throw InputError(SourceLocation{path, e.mark.line + 1}.prefix() + "not valid YAML: " + e.msg);
  }
}

/// The flow-style sequence [a, b] (positions, points and velocities of generated models).
inline YAML::Node flow_pair(double a, double b) {
  YAML::Node n(YAML::NodeType::Sequence);
  n.push_back(a);
  n.push_back(b);
  n.SetStyle(YAML::EmitterStyle::Flow);
  return n;
}

/// The 1-based line of a node (0: unknown).
inline int yaml_line(const YAML::Node& node) { return node && !node.Mark().is_null() ? node.Mark().line + 1 : 0; }

/// Throws InputError "path:line: message" at the node.
[[noreturn]] inline void yaml_error(const std::string& path, const YAML::Node& node, const std::string& message) {
  throw InputError(SourceLocation{path, yaml_line(node)}.prefix() + message);
}

}  // namespace railcrash
