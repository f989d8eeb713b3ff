#include "railcrash/element_registry.hpp"

namespace railcrash {

double ParameterReader::required(const std::string& key) {
  const auto value = number(key);
  if (!value) fail(key, "missing required parameter '" + key + "'");
  return *value;
}

double ParameterReader::required_positive(const std::string& key) {
  const double value = required(key);
  if (!(value > 0.0)) fail(key, "'" + key + "' must be positive");
  return value;
}

double ParameterReader::required_nonnegative(const std::string& key) {
  const double value = required(key);
  if (value < 0.0) fail(key, "'" + key + "' must not be negative");
  return value;
}

std::optional<double> ParameterReader::optional_nonnegative(const std::string& key) {
  const auto value = number(key);
  if (value && *value < 0.0) fail(key, "'" + key + "' must not be negative");
  return value;
}

std::optional<double> ParameterReader::optional_positive(const std::string& key) {
  const auto value = number(key);
  if (value && !(*value > 0.0)) fail(key, "'" + key + "' must be positive");
  return value;
}

void ElementSpec::require_points(std::size_t count) const {
  if (points.size() != count)
    throw InputError(where.prefix() + "element '" + name + "' (" + type + ") needs exactly " + std::to_string(count) +
                     " points, found " + std::to_string(points.size()));
}

const ElementRegistry& ElementRegistry::instance() {
  static const ElementRegistry registry = [] {
    ElementRegistry r;
    register_spring_elements(r);
    register_joint_elements(r);
    register_crush_elements(r);
    register_nonlinear_elements(r);
    register_couplers_elements(r);
    register_beams_elements(r);
    register_anticlimber_elements(r);
    register_contact_elements(r);
    return r;
  }();
  return registry;
}

void ElementRegistry::add(const std::string& type, ElementFactory factory) { factories_[type] = std::move(factory); }

const ElementFactory* ElementRegistry::find(const std::string& type) const {
  const auto it = factories_.find(type);
  return it == factories_.end() ? nullptr : &it->second;
}

std::vector<std::string> ElementRegistry::types() const {
  std::vector<std::string> out;
  for (const auto& entry : factories_) out.push_back(entry.first);
  return out;
}

}  // namespace railcrash
