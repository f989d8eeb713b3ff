#include "railcrash/model/element_registry.hpp"

#include <cstdio>
#include <stdexcept>

namespace railcrash {

const char* unit_kind_name(Unit unit) {
  switch (unit) {
    case Unit::Dimensionless: return "dimensionless";
    case Unit::Length: return "length";
    case Unit::Angle: return "angle";
    case Unit::Force: return "force";
    case Unit::Moment: return "moment";
    case Unit::ForcePerLength: return "force/length";
    case Unit::MomentPerAngle: return "moment/angle";
    case Unit::ForceTimePerLength: return "force*time/length";
    case Unit::MomentTimePerAngle: return "moment*time/angle";
    case Unit::Velocity: return "velocity";
    case Unit::AngularVelocity: return "angular velocity";
    case Unit::Stress: return "stress";
    case Unit::Area: return "area";
    case Unit::SectionModulus: return "section modulus";
    case Unit::SecondMoment: return "second moment of area";
    case Unit::Direction: return "direction [x, y]";
    case Unit::Position: return "position [x, y]";
    case Unit::LengthForceCurve: return "curve [[length, force], ...]";
    case Unit::Choice: return "choice";
  }
  return "";
}

const char* unit_symbol(Unit unit, UnitSystem units) {
  const bool si = units == UnitSystem::SI;
  switch (unit) {
    case Unit::Dimensionless:
    case Unit::Direction:
    case Unit::Choice: return "";
    case Unit::Length:
    case Unit::Position: return si ? "m" : "in";
    case Unit::Angle: return "rad";
    case Unit::Force: return si ? "N" : "lbf";
    case Unit::Moment: return si ? "N*m" : "lbf*in";
    case Unit::ForcePerLength: return si ? "N/m" : "lbf/in";
    case Unit::MomentPerAngle: return si ? "N*m/rad" : "lbf*in/rad";
    case Unit::ForceTimePerLength: return si ? "N*s/m" : "lbf*s/in";
    case Unit::MomentTimePerAngle: return si ? "N*m*s/rad" : "lbf*in*s/rad";
    case Unit::Velocity: return si ? "m/s" : "in/s";
    case Unit::AngularVelocity: return "rad/s";
    case Unit::Stress: return si ? "Pa" : "psi";
    case Unit::Area: return si ? "m^2" : "in^2";
    case Unit::SectionModulus: return si ? "m^3" : "in^3";
    case Unit::SecondMoment: return si ? "m^4" : "in^4";
    case Unit::LengthForceCurve: return si ? "[[m, N], ...]" : "[[in, lbf], ...]";
  }
  return "";
}

const char* range_text(Range range) {
  switch (range) {
    case Range::Any: return "";
    case Range::Positive: return "> 0";
    case Range::NonNegative: return ">= 0";
    case Range::Fraction: return "0 < x <= 1";
    case Range::UnitInterval: return "0 <= x <= 1";
  }
  return "";
}

const Presence required{Presence::Required, 0.0, "", std::nullopt};

Presence optional(std::string when_absent) { return {Presence::Optional, 0.0, std::move(when_absent), std::nullopt}; }

Presence default_value(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return {Presence::Default, value, text, std::nullopt};
}

Presence default_velocity(double inches_per_second) {
  const double metres_per_second = inches_per_second * metres_per_length_unit(UnitSystem::InLbfS);
  char text[128];
  std::snprintf(text, sizeof text, "%g in/s (in-lbf-s), %g m/s (SI), %g mm/s (mm-t-s-N): one speed", inches_per_second,
                metres_per_second, 1e3 * metres_per_second);
  return {Presence::Default, inches_per_second, text, metres_per_second};
}

Presence default_flag(bool value) { return {Presence::Default, value ? 1.0 : 0.0, value ? "true" : "false", std::nullopt}; }

Presence default_word(std::string word) { return {Presence::Default, 0.0, std::move(word), std::nullopt}; }

const ParameterSpec* ElementType::find(const std::string& key) const {
  for (const ParameterSpec& spec : parameters)
    if (spec.name == key) return &spec;
  return nullptr;
}

std::vector<std::string> ElementType::keys() const {
  std::vector<std::string> out;
  for (const ParameterSpec& spec : parameters) out.push_back(spec.name);
  return out;
}

// ---- ParameterReader ----------------------------------------------------------------------

namespace {

const char* shape_name(Shape shape) {
  switch (shape) {
    case Shape::Number: return "number";
    case Shape::Pair: return "vector";
    case Shape::Table: return "table";
    case Shape::Flag: return "flag";
    case Shape::Word: return "word";
  }
  return "";
}

}  // namespace

const ParameterSpec& ParameterReader::declared(const std::string& key, Shape shape) const {
  const ParameterSpec* spec = type_.find(key);
  if (!spec) throw std::logic_error("element type '" + type_.name + "' reads parameter '" + key + "', which it does not declare");
  if (spec->shape != shape)
    throw std::logic_error("element type '" + type_.name + "' reads parameter '" + key + "' as a " + shape_name(shape) +
                           " but declares it as a " + shape_name(spec->shape));
  return *spec;
}

std::string ParameterReader::described(const ParameterSpec& spec) const {
  const std::string symbol = unit_symbol(spec.unit, units_);
  return " (" + std::string(unit_kind_name(spec.unit)) + (symbol.empty() ? "" : " [" + symbol + "]") + ": " +
         spec.meaning + ")";
}

void ParameterReader::check_range(const ParameterSpec& spec, double value) const {
  const std::string& key = spec.name;
  char given[40];
  std::snprintf(given, sizeof given, "%g", value);
  switch (spec.range) {
    case Range::Any: return;
    case Range::Positive:
      if (!(value > 0.0)) fail(key, "'" + key + "' must be positive, not " + given + described(spec));
      return;
    case Range::NonNegative:
      if (value < 0.0) fail(key, "'" + key + "' must not be negative, not " + given + described(spec));
      return;
    case Range::Fraction:
      if (!(value > 0.0 && value <= 1.0)) fail(key, "'" + key + "' must be above 0 and at most 1, not " + given + described(spec));
      return;
    case Range::UnitInterval:
      if (!(value >= 0.0 && value <= 1.0)) fail(key, "'" + key + "' must be between 0 and 1, not " + given + described(spec));
      return;
  }
}

std::optional<double> ParameterReader::number(const std::string& key) {
  const ParameterSpec& spec = declared(key, Shape::Number);
  const std::optional<double> given = given_number(key);
  if (!given) return spec.presence.kind == Presence::Default ? std::optional<double>(spec.presence.value_in(units_)) : std::nullopt;
  check_range(spec, *given);
  return given;
}

double ParameterReader::value(const std::string& key) {
  const ParameterSpec& spec = declared(key, Shape::Number);
  if (spec.presence.kind == Presence::Optional)
    throw std::logic_error("element type '" + type_.name + "' reads optional parameter '" + key +
                           "' as required; read it with number()");
  const std::optional<double> result = number(key);
  if (!result) fail(key, "missing required parameter '" + key + "'" + described(spec));
  return *result;
}

std::optional<std::vector<double>> ParameterReader::vector(const std::string& key, std::size_t size) {
  const ParameterSpec& spec = declared(key, Shape::Pair);
  auto given = given_vector(key, size);
  if (!given && spec.presence.kind == Presence::Required) fail(key, "missing required parameter '" + key + "'" + described(spec));
  if (given)
    for (double v : *given) check_range(spec, v);
  return given;
}

std::optional<std::vector<std::vector<double>>> ParameterReader::table(const std::string& key, std::size_t width) {
  const ParameterSpec& spec = declared(key, Shape::Table);
  auto given = given_table(key, width);
  if (!given && spec.presence.kind == Presence::Required) fail(key, "missing required parameter '" + key + "'" + described(spec));
  if (given)
    for (const auto& row : *given)
      for (double v : row) check_range(spec, v);
  return given;
}

std::optional<bool> ParameterReader::flag(const std::string& key) {
  const ParameterSpec& spec = declared(key, Shape::Flag);
  const std::optional<bool> given = given_flag(key);
  if (!given && spec.presence.kind == Presence::Default) return spec.presence.value != 0.0;
  return given;
}

std::optional<std::string> ParameterReader::word(const std::string& key) {
  const ParameterSpec& spec = declared(key, Shape::Word);
  std::optional<std::string> given = given_word(key);
  if (!given && spec.presence.kind == Presence::Default) return spec.presence.text;
  return given;
}

// ---- ElementRegistry ------------------------------------------------------------------------

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

void ElementRegistry::add(ElementType type) {
  const std::string name = type.name;
  types_[name] = std::move(type);
}

const ElementType* ElementRegistry::find(const std::string& type) const {
  const auto it = types_.find(type);
  return it == types_.end() ? nullptr : &it->second;
}

std::vector<std::string> ElementRegistry::types() const {
  std::vector<std::string> out;
  for (const auto& entry : types_) out.push_back(entry.first);
  return out;
}

}  // namespace railcrash
