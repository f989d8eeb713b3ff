// Element types by name. Each element family declares its types (points, parameters with
// unit kind, default, range and meaning, a summary of the law) next to their factories;
// the declarations are the one source of the loader's key checks, its messages,
// `railcrash elements` and docs/elements.md. A factory reads its parameters through a
// ParameterReader, which only hands out declared keys, applies their defaults and checks
// their ranges (and knows the file and line of every key, so messages point at it).
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "railcrash/model/element.hpp"
#include "railcrash/model/model.hpp"

namespace railcrash {

/// Physical kind of a parameter, printed in both unit systems of the model format.
enum class Unit {
  Dimensionless,
  Length,
  Angle,             // [rad]
  Force,
  Moment,            // force x length
  ForcePerLength,    // stiffness
  MomentPerAngle,    // rotational stiffness
  ForceTimePerLength,    // damping
  MomentTimePerAngle,    // rotational damping
  Velocity,
  AngularVelocity,
  Stress,            // force / length^2
  Area,
  SectionModulus,    // length^3
  SecondMoment,      // length^4
  Direction,         // [x, y] in body 1's frame (scaled to length 1)
  Position,          // [x, y] global
  LengthForceCurve,  // [[length, force], ...]
  Choice,            // a word or a number from a fixed set (see the meaning)
};
/// "force/length"
const char* unit_kind_name(Unit unit);
/// "lbf/in" (in-lbf-s) or "N/m" (SI); "" for dimensionless and choices.
const char* unit_symbol(Unit unit, UnitSystem units);

/// Allowed values of a number (of every number in a vector).
enum class Range { Any, Positive, NonNegative, Fraction /* (0, 1] */, UnitInterval /* [0, 1] */ };
/// "> 0", ">= 0", "0 < x <= 1", ...; "" for Any.
const char* range_text(Range range);

/// What a parameter holds in the model file.
enum class Shape { Number, Pair /* [a, b] */, Table /* [[a, b], ...] */, Flag, Word };

/// Whether a parameter must be given, and what applies when it is not.
struct Presence {
  enum Kind { Required, Optional, Default } kind = Required;
  double value = 0.0;       // Default: the value applied (a number; a flag as 0 / 1); in-lbf-s where si_value is set
  std::string text;         // Optional: what its absence means; Default: the value as written
  std::optional<double> si_value;  // Default: the value applied in an SI (or mm-t-s-N) model, where it differs
  /// The default in a model of unit system `units`.
  double value_in(UnitSystem units) const { return units == UnitSystem::SI && si_value ? *si_value : value; }
};
extern const Presence required;
/// Absent means `when_absent` (e.g. "the initial length", "no fracture"); the factory decides.
Presence optional(std::string when_absent);
/// Absent means `value` (the reader hands it out).
Presence default_value(double value);
/// A velocity's default: `inches_per_second` in an in-lbf-s model, the same speed in m/s in an
/// SI model (and so in an mm-t-s-N one, read into SI). A plain default_value of a dimensional
/// quantity would mean a speed 39 times larger in SI than in inches: the same physical model
/// would behave differently with its units.
Presence default_velocity(double inches_per_second);
Presence default_flag(bool value);
Presence default_word(std::string word);

struct ParameterSpec {
  std::string name;
  Unit unit = Unit::Dimensionless;
  Presence presence;
  Range range = Range::Any;
  std::string meaning;  // one line
  Shape shape = Shape::Number;
};

class ParameterReader;
struct ElementSpec;
using ElementFactory = std::function<std::unique_ptr<Element>(ElementSpec&)>;

/// One element type: what it takes, what it does, and how to make one.
struct ElementType {
  std::string name;
  std::string report_type;    // the IITRAIN report's element type number(s), "" when new
  std::size_t points = 2;
  std::string points_meaning;  // what P1 (and P2) are
  std::string summary;         // the law, one paragraph (from the element's header)
  std::vector<ParameterSpec> parameters;
  std::string example;         // parameter lines of a valid element ("key: value" per line)
  ElementFactory factory;

  const ParameterSpec* find(const std::string& key) const;
  std::vector<std::string> keys() const;
};

/// Read access to one element's parameters, as its type declares them. Reading a key the
/// type does not declare (or as another shape) is a programming error (std::logic_error).
/// Numbers are checked against the declared range; absent keys with a declared default
/// give the default; `value` of an absent required key fails with the standard message.
class ParameterReader {
 public:
  /// `units`: the model's unit system, for the units named in messages.
  ParameterReader(const ElementType& type, UnitSystem units) : type_(type), units_(units) {}
  virtual ~ParameterReader() = default;

  /// The number (the default when absent), or nullopt when absent without a default.
  std::optional<double> number(const std::string& key);
  /// A required number, or one with a default.
  double value(const std::string& key);
  /// A list of exactly `size` numbers (size 0: any length), each in range, or nullopt.
  std::optional<std::vector<double>> vector(const std::string& key, std::size_t size);
  /// A table of rows of exactly `width` numbers ([[a, b], ...]), or nullopt.
  std::optional<std::vector<std::vector<double>>> table(const std::string& key, std::size_t width);
  /// The flag (the default when absent).
  std::optional<bool> flag(const std::string& key);
  /// A word (a YAML scalar, e.g. `release`); the default when absent.
  std::optional<std::string> word(const std::string& key);
  /// Throws an InputError located at `key` (or at the element when the key is absent).
  [[noreturn]] virtual void fail(const std::string& key, const std::string& what_to_change) const = 0;

  const ElementType& type() const { return type_; }

 protected:
  // The file's values, unchecked against the declaration (nullopt when absent).
  virtual std::optional<double> given_number(const std::string& key) = 0;
  virtual std::optional<std::vector<double>> given_vector(const std::string& key, std::size_t size) = 0;
  virtual std::optional<std::vector<std::vector<double>>> given_table(const std::string& key, std::size_t width) = 0;
  virtual std::optional<bool> given_flag(const std::string& key) = 0;
  virtual std::optional<std::string> given_word(const std::string& key) = 0;

 private:
  const ParameterSpec& declared(const std::string& key, Shape shape) const;
  void check_range(const ParameterSpec& spec, double value) const;
  /// " (force/length [lbf/in]: spring rate)": the kind, unit and meaning of a key, for messages.
  std::string described(const ParameterSpec& spec) const;

  const ElementType& type_;
  UnitSystem units_;
};

/// What a factory gets: the element's name, type, points (as many as the type declares: the
/// loader checks the count) and its parameters.
struct ElementSpec {
  std::string name;
  std::string type;
  std::vector<PointRef> points;
  SourceLocation where;
  ParameterReader* parameters = nullptr;
};

class ElementRegistry {
 public:
  /// All element types railcrash knows.
  static const ElementRegistry& instance();

  void add(ElementType type);
  const ElementType* find(const std::string& type) const;
  std::vector<std::string> types() const;

 private:
  std::map<std::string, ElementType> types_;
};

// One registration function per element family (src/elements/*.cpp).
void register_spring_elements(ElementRegistry& registry);
void register_joint_elements(ElementRegistry& registry);
void register_crush_elements(ElementRegistry& registry);
void register_nonlinear_elements(ElementRegistry& registry);
void register_couplers_elements(ElementRegistry& registry);
void register_beams_elements(ElementRegistry& registry);
void register_anticlimber_elements(ElementRegistry& registry);
void register_contact_elements(ElementRegistry& registry);

}  // namespace railcrash
