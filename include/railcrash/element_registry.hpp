// Element types by name: each element family registers a factory that reads its
// parameters through a ParameterReader (which knows the file and line of every key, so
// the factory's checks produce messages that point at the right place).
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "railcrash/element.hpp"

namespace railcrash {

/// Read access to one element's parameters. Every key read is marked as used; the loader
/// rejects keys nobody read (typos), listing what the type accepts.
class ParameterReader {
 public:
  virtual ~ParameterReader() = default;
  /// A finite number, or nullopt when the key is absent.
  virtual std::optional<double> number(const std::string& key) = 0;
  /// A list of exactly `size` finite numbers (size 0: any length), or nullopt.
  virtual std::optional<std::vector<double>> vector(const std::string& key, std::size_t size) = 0;
  /// A table of rows of exactly `width` finite numbers ([[a, b], ...]), or nullopt.
  virtual std::optional<std::vector<std::vector<double>>> table(const std::string& key, std::size_t width) = 0;
  virtual std::optional<bool> flag(const std::string& key) = 0;
  /// A word (a YAML scalar, e.g. `release`), or nullopt when the key is absent.
  virtual std::optional<std::string> word(const std::string& key) = 0;
  /// Throws an InputError located at `key` (or at the element when the key is absent).
  [[noreturn]] virtual void fail(const std::string& key, const std::string& what_to_change) const = 0;

  double required(const std::string& key);
  double required_positive(const std::string& key);
  double required_nonnegative(const std::string& key);
  std::optional<double> optional_nonnegative(const std::string& key);
  std::optional<double> optional_positive(const std::string& key);
};

struct ElementSpec {
  std::string name;
  std::string type;
  std::vector<PointRef> points;
  SourceLocation where;
  ParameterReader* parameters = nullptr;

  /// Throws unless the element has exactly `count` points.
  void require_points(std::size_t count) const;
};

using ElementFactory = std::function<std::unique_ptr<Element>(ElementSpec&)>;

class ElementRegistry {
 public:
  /// All element types railcrash knows.
  static const ElementRegistry& instance();

  void add(const std::string& type, ElementFactory factory);
  const ElementFactory* find(const std::string& type) const;
  std::vector<std::string> types() const;

 private:
  std::map<std::string, ElementFactory> factories_;
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
