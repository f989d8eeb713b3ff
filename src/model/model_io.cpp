#include "railcrash/model/model_io.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cstdlib>
#include <cstdio>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <tuple>
#include <unordered_set>

#include "railcrash/core/sha256.hpp"
#include "railcrash/model/element_registry.hpp"
#include "railcrash/model/train_expansion.hpp"
#include "railcrash/model/yaml_file.hpp"
#include "railcrash/model/yaml_reader.hpp"

namespace railcrash {

namespace {
std::string join(const std::vector<std::string>& words) { return join_words(words); }
}  // namespace

std::string name_length_problem(const std::string& what, const std::string& name) {
  std::size_t characters = 0;  // UTF-8 code points: every byte but the continuation bytes
  for (const char c : name) characters += (static_cast<unsigned char>(c) & 0xC0) != 0x80;
  if (characters <= kMaxNameLength) return "";
  constexpr std::size_t kShown = 40;
  std::string head;
  for (std::size_t i = 0; i < name.size() && i < kShown; ++i)  // bytes; anything but plain ASCII shown as '?'
    head += static_cast<unsigned char>(name[i]) < 0x20 || static_cast<unsigned char>(name[i]) >= 0x7F ? '?' : name[i];
  return what + " '" + head + "...' (its first " + std::to_string(kShown) + " characters) is " + std::to_string(characters) +
         " characters long, more than the limit of " + std::to_string(kMaxNameLength) + " (model_io.hpp kMaxNameLength); shorten it";
}

namespace {

/// Reads one model file, keeping the file name for every message (the checks: YamlReader); a
/// node that came from a setting or a car type's copy is reported where it came from.
class Reader : public YamlReader {
 public:
  explicit Reader(std::string file) : YamlReader(std::move(file)) {}

  /// Marks `value` (and everything inside it) as coming from a setting: its line numbers
  /// belong to the setting, not to the file. `setting` is the prefix of the messages about it
  /// (e.g. "model.yaml: --set 'k=2'" or "variant.yaml:12: set 'k'").
  void add_override(const YAML::Node& value, const std::string& setting) {
    overridden_.emplace_back(value, setting);
    if (value.IsSequence() || value.IsMap())
      for (const auto& entry : value) {
        if (value.IsMap()) {
          add_override(entry.first, setting);
          add_override(entry.second, setting);
        } else {
          add_override(entry, setting);
        }
      }
  }

  /// Remembers the line of the key of every empty value ("t_end:" with nothing after it):
  /// yaml-cpp places an empty value where the next token starts, often the next line.
  /// Each list or map is walked once: an alias (*name) is the anchored node itself, at the
  /// anchor's place in the text, so a document of aliases costs its text, not its expansion.
  void index_empty_values(const YAML::Node& node) {
    if ((node.IsMap() || node.IsSequence()) && !node.Mark().is_null() && !walked_positions_.insert(node.Mark().pos).second) {
      shared_positions_.insert(node.Mark().pos);  // met again: an alias
      return;
    }
    if (node.IsMap()) {
      for (const auto& entry : node) {
        if (entry.second.IsNull() && !entry.first.Mark().is_null()) empty_values_.emplace_back(entry.second, entry.first.Mark().line + 1);
        index_empty_values(entry.second);
      }
    } else if (node.IsSequence()) {
      for (const auto& item : node) index_empty_values(item);
    }
  }

  /// Whether the list or map `node` may be reached from more than one place of the document, so
  /// that changing it in place would change those places too: a node an alias (*name) refers to
  /// (index_empty_values met it twice), or an entry of a list or map that an edit copied (the
  /// copy and the original both hold it). A node that lies inside such a node is reached through
  /// it: the editor (put_value) copies everything below the first shared node of a path.
  bool shared(const YAML::Node& node) const {
    if (!node.IsMap() && !node.IsSequence()) return false;
    if (!node.Mark().is_null() && shared_positions_.count(node.Mark().pos)) return true;
    for (const YAML::Node& entry : copied_entries_)
      if (entry.is(node)) return true;
    return false;
  }

  /// Registers `copy`, a list or map an edit made from one of the document (one level deep),
  /// as coming from `setting` (it has no line in the file), and its lists and maps as shared
  /// with the original.
  void add_copy(const YAML::Node& copy, const std::string& setting) {
    overridden_.emplace_back(copy, setting);
    for (const auto& entry : copy) {
      const YAML::Node value = copy.IsMap() ? entry.second : YAML::Node(entry);
      if (value.IsMap() || value.IsSequence()) copied_entries_.push_back(value);
    }
  }

  /// Whether `value` came from a setting (--set, a command-line option, a variant's set).
  bool overridden(const YAML::Node& value) const { return from_override(value) != nullptr; }

  SourceLocation at(const YAML::Node& node) const {
    if (!node.IsDefined() || from_override(node)) return {file(), 0};
    if (expansion_)
      if (const TrainExpansion::Origin* origin = expansion_->origin(node)) return {file(), origin->line};
    if (node.IsNull())
      for (const auto& entry : empty_values_)
        if (entry.first.is(node)) return {file(), entry.second};
    if (node.Mark().is_null()) return {file(), 0};
    return {file(), node.Mark().line + 1};
  }
  [[noreturn]] void fail(const YAML::Node& node, const std::string& message) const override {
    if (const std::string* setting = from_override(node)) throw InputError(*setting + ": " + message);
    if (expansion_)  // a copy of a car type's text: its line, and the instance
      if (const TrainExpansion::Origin* origin = expansion_->origin(node)) throw InputError(at(node).prefix() + message + *origin->note);
    throw InputError(at(node).prefix() + message);
  }

  /// The setting (its label) `node` came from, or nullptr when it is from the file.
  const std::string* setting_of(const YAML::Node& node) const { return from_override(node); }
  /// The expansion of the file's car types and trains: where its generated nodes came from.
  void set_expansion(const TrainExpansion* expansion) { expansion_ = expansion; }

  /// Factors from the file's units to the model's (mm-t-s-N: to SI; otherwise 1).
  struct UnitScale {
    double length = 1.0, mass = 1.0, force = 1.0;
    /// The factor of a parameter of unit kind `unit` (a curve's: of its length column).
    double of(Unit unit) const {
      const double l = length, f = force;
      switch (unit) {
        case Unit::Length: case Unit::Position: case Unit::Velocity: case Unit::LengthForceCurve: return l;
        case Unit::Force: return f;
        case Unit::Moment: case Unit::MomentPerAngle: case Unit::MomentTimePerAngle: return f * l;
        case Unit::ForcePerLength: case Unit::ForceTimePerLength: return f / l;
        case Unit::Stress: return f / (l * l);
        case Unit::Area: return l * l;
        case Unit::SectionModulus: return l * l * l;
        case Unit::SecondMoment: return l * l * l * l;
        default: return 1.0;  // dimensionless, angles, angular velocities, directions, choices
      }
    }
  };
  void set_scale(UnitScale scale) { scale_ = scale; }
  const UnitScale& scale() const { return scale_; }

 private:
  /// The --set setting `node` came from, or nullptr when it is from the file.
  const std::string* from_override(const YAML::Node& node) const {
    if (!node.IsDefined()) return nullptr;
    for (const auto& entry : overridden_)
      if (entry.first.is(node)) return &entry.second;
    return nullptr;
  }

  std::vector<std::pair<YAML::Node, std::string>> overridden_;
  std::vector<std::pair<YAML::Node, int>> empty_values_;
  std::unordered_set<int> walked_positions_;  // text positions of the lists and maps index_empty_values walked
  std::unordered_set<int> shared_positions_;  // ... of those it met more than once (an alias refers to them)
  std::vector<YAML::Node> copied_entries_;     // lists and maps held by an edit's copy and by the original
  const TrainExpansion* expansion_ = nullptr;
  UnitScale scale_;
};

class YamlParameterReader : public ParameterReader {
 public:
  YamlParameterReader(const ElementType& type, UnitSystem units, const Reader& reader, const YAML::Node& element,
                      std::string context)
      : ParameterReader(type, units), reader_(reader), element_(element), context_(std::move(context)) {}

  std::optional<double> given_number(const std::string& key) override {
    const YAML::Node node = element_[key];
    if (!node) return std::nullopt;
    return reader_.number(node, context_ + ": '" + key + "'") * factor(key);
  }
  std::optional<std::vector<double>> given_vector(const std::string& key, std::size_t size) override {
    const YAML::Node node = element_[key];
    if (!node) return std::nullopt;
    std::vector<double> values = reader_.numbers(node, size, context_ + ": '" + key + "'");
    for (double& v : values) v *= factor(key);
    return values;
  }
  std::optional<std::vector<std::vector<double>>> given_table(const std::string& key, std::size_t width) override {
    const YAML::Node node = element_[key];
    if (!node) return std::nullopt;
    if (!node.IsSequence() || node.size() == 0)
      reader_.fail(node, context_ + ": '" + key + "' must be a table of rows [[a, b], ...]");
    std::vector<std::vector<double>> rows;
    const ParameterSpec* spec = type().find(key);
    const bool curve = spec && spec->unit == Unit::LengthForceCurve;  // [[length, force], ...]
    for (std::size_t i = 0; i < node.size(); ++i) {
      rows.push_back(reader_.numbers(node[i], width, context_ + ": '" + key + "' row " + std::to_string(i + 1)));
      for (std::size_t k = 0; k < rows.back().size(); ++k)
        rows.back()[k] *= curve && k > 0 ? reader_.scale().force : factor(key);
    }
    return rows;
  }
  std::optional<bool> given_flag(const std::string& key) override {
    const YAML::Node node = element_[key];
    if (!node) return std::nullopt;
    return reader_.boolean(node, context_ + ": '" + key + "'");
  }
  std::optional<std::string> given_word(const std::string& key) override {
    const YAML::Node node = element_[key];
    if (!node) return std::nullopt;
    return reader_.text(node, context_ + ": '" + key + "'");
  }
  [[noreturn]] void fail(const std::string& key, const std::string& what_to_change) const override {
    const YAML::Node node = element_[key];
    reader_.fail(node ? node : element_, context_ + ": " + what_to_change);
    std::abort();  // not reached (Reader::fail throws); GCC's sanitizer build cannot see it through the virtual call
  }

 private:
  /// From the file's units to the model's, for `key`'s unit kind.
  double factor(const std::string& key) const {
    const ParameterSpec* spec = type().find(key);
    return spec ? reader_.scale().of(spec->unit) : 1.0;
  }

  const Reader& reader_;
  YAML::Node element_;
  std::string context_;
};

/// One step from a list or map of the document to one of its entries.
struct DocumentStep {
  std::string key;                   // a map's key (when index is empty)
  std::optional<std::size_t> index;  // a list's entry, from 0
};

/// The node at the first `steps` steps of `path` below `root` (undefined when one is missing).
YAML::Node node_at(const YAML::Node& root, const std::vector<DocumentStep>& path, std::size_t steps) {
  YAML::Node node = root;
  for (std::size_t k = 0; k < steps; ++k) {
    const YAML::Node& holder = node;  // const: a missing key is not added
    const YAML::Node entry = path[k].index ? holder[*path[k].index] : holder[path[k].key];
    if (!entry.IsDefined()) return YAML::Node(YAML::NodeType::Undefined);
    node.reset(entry);  // not =: assigning a node writes the entry into the node it was
  }
  return node;
}

/// A copy of the list or map `container`, one level deep (its entries are the same nodes), with
/// the entry at `step` replaced by `replacement` (or, in a map without it, added).
YAML::Node copy_replacing(const YAML::Node& container, const DocumentStep& step, const YAML::Node& replacement) {
  YAML::Node copy(container.IsSequence() ? YAML::NodeType::Sequence : YAML::NodeType::Map);
  bool replaced = false;
  if (container.IsSequence()) {
    for (std::size_t i = 0; i < container.size(); ++i) {
      replaced = replaced || i == *step.index;
      copy.push_back(i == *step.index ? replacement : YAML::Node(container[i]));
    }
  } else {
    for (const auto& entry : container) {
      const bool edited = entry.first.IsScalar() && entry.first.Scalar() == step.key;
      replaced = replaced || edited;
      copy.force_insert(entry.first, edited ? replacement : entry.second);
    }
    if (!replaced) copy.force_insert(step.key, replacement);
  }
  copy.SetStyle(container.Style());
  return copy;
}

/// Puts `value` at `path` in the document `root`, so that the place the path names changes and
/// no other. yaml-cpp makes an alias (*name) the very node its anchor (&name) labels, and
/// assigning to a node (node = value, node = "2") changes it wherever it appears. So a value is
/// never assigned through the node it replaces: the map that holds it drops the old entry and
/// takes the new one, and the lists and maps on the path from the first shared one down
/// (Reader::shared) are copied one level deep, each copy taking the old one's place in the level
/// above. A list's entry is replaced by copying the list. A copy has no line in the file:
/// messages about it name `setting`. The key that names an edited value below the top level is
/// marked as the setting's (an unknown key given with --set is reported against the setting).
void put_value(const YAML::Node& root, const std::vector<DocumentStep>& path, const YAML::Node& value, Reader& reader,
               const std::string& setting) {
  std::vector<YAML::Node> containers;  // containers[k]: the list or map that step k goes into
  for (std::size_t k = 0; k < path.size(); ++k) containers.push_back(node_at(root, path, k));
  std::size_t first_copied = containers.size();
  for (std::size_t k = 1; k < containers.size(); ++k)
    if (reader.shared(containers[k])) {
      first_copied = k;
      break;
    }
  YAML::Node replacement = value;
  for (std::size_t k = containers.size(); k-- > 0;) {
    YAML::Node container = containers[k];
    const DocumentStep& step = path[k];
    if (k < first_copied && !step.index) {
      const YAML::Node& map = container;
      if (map.IsMap() && map[step.key]) container.remove(step.key);
      container.force_insert(step.key, replacement);
      if (k > 0 && k + 1 == containers.size())
        for (const auto& entry : container)
          if (entry.second.is(replacement)) reader.add_override(entry.first, setting);
      return;
    }
    YAML::Node copy = copy_replacing(container, step, replacement);
    reader.add_copy(copy, setting);
    replacement.reset(copy);
  }
}

/// The names of the items of the document's lists `sections` (bodies, elements).
std::vector<std::string> names_in(const YAML::Node& document, std::initializer_list<const char*> sections) {
  std::vector<std::string> names;
  for (const char* section : sections) {
    const YAML::Node list = document[section];
    if (!list || !list.IsSequence()) continue;
    for (const YAML::Node& item : list)
      if (item.IsMap() && item["name"] && item["name"].IsScalar()) names.push_back(item["name"].Scalar());
  }
  return names;
}

bool has_dotted_name(const std::vector<std::string>& names) {
  return std::any_of(names.begin(), names.end(), [](const std::string& name) { return name.find('.') != std::string::npos; });
}

/// A KEY's parts from `first` up to the last one (its key) joined by dots: the name of a body
/// or element, which may hold dots itself (unitA.car2.body).
std::string name_before_key(const std::vector<std::string>& parts, std::size_t first) {
  std::string name = parts[first];
  for (std::size_t k = first + 1; k + 1 < parts.size(); ++k) name += "." + parts[k];
  return name;
}

/// The path a setting's KEY names (simulation.t_end, bodies.<name>.<key>, elements.<name>.<key>,
/// a top-level key, each optionally followed by [INDEX] for an entry of a list: gravity[1],
/// bodies.cart.velocity[0]). The lists and maps on the way must exist; the last key may be new
/// (KEY=VALUE; `for_scaling` false), an index must be an entry of a list. `where` starts the
/// messages.
std::vector<DocumentStep> setting_path(YAML::Node& root, const std::string& key, bool for_scaling, const std::string& where) {
  const auto bracket = key.find('[');
  std::vector<std::size_t> indices;
  for (std::size_t at = bracket; at != std::string::npos && at < key.size();) {
    const std::size_t close = key.find(']', at);
    const std::string digits = close == std::string::npos ? "" : key.substr(at + 1, close - at - 1);
    if (key[at] != '[' || digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos || digits.size() > 9)
      throw InputError(where + "write an entry of a list as KEY[INDEX] (from 0), e.g. bodies.car1_center_body.velocity[0], "
                               "not '" + key + "'");
    indices.push_back(std::stoul(digits));
    at = close + 1;
  }
  const std::string name = key.substr(0, bracket);
  std::vector<std::string> parts;
  std::stringstream stream(name);
  for (std::string part; std::getline(stream, part, '.');) parts.push_back(part);
  const std::string no_number = "there is no number at '" + name +
                                "' to scale (KEY is section.key, bodies.<name>.<key> or elements.<name>.<key>, "
                                "optionally with [INDEX] for an entry of a list)";
  const YAML::Node& document = root;  // const: looking a key up does not add it
  std::vector<DocumentStep> path;
  if (parts.size() == 1 && !name.empty()) {
    path = {{parts[0], {}}};
  } else if (parts.size() == 2) {
    if (document[parts[0]] && !document[parts[0]].IsMap()) {
      if (for_scaling) throw InputError(where + no_number);
      if (parts[0] == "bodies" || parts[0] == "elements")
        throw InputError(where + "'" + parts[0] + "' is a list; use " + parts[0] + ".<name>.<key>, e.g. " +
                         (parts[0] == "bodies" ? "bodies.cart.mass=2" : "elements.spring.stiffness=200"));
      throw InputError(where + "'" + parts[0] + "' is not a section of keys; give it whole, e.g. " + parts[0] + "=VALUE");
    }
    if (!document[parts[0]]) {
      if (for_scaling || !indices.empty()) throw InputError(where + (for_scaling ? no_number : "the model has no '" + parts[0] + "' section"));
      if (parts[0] != "simulation")
        throw InputError(where + "'" + parts[0] + "' is not a section of keys; the section is simulation (e.g. simulation.t_end=0.5)");
      root[parts[0]] = YAML::Node(YAML::NodeType::Map);
    }
    path = {{parts[0], {}}, {parts[1], {}}};
  } else if (parts.size() >= 3 && (parts[0] == "bodies" || parts[0] == "elements")) {
    // bodies.<name>.<key>: the name is everything between the section and the last key, so a
    // name with dots is found too (a train's car's body: bodies.unitA.car2.body.mass).
    const std::string item_name = name_before_key(parts, 1);
    const YAML::Node list = document[parts[0]];
    if (list && list.IsSequence())
      for (std::size_t i = 0; i < list.size() && path.empty(); ++i)
        if (list[i].IsMap() && list[i]["name"] && list[i]["name"].IsScalar() && list[i]["name"].Scalar() == item_name)
          path = {{parts[0], {}}, {"", i}, {parts.back(), {}}};
    if (path.empty())
      throw InputError(where + (for_scaling ? no_number : "the model has no " + std::string(parts[0] == "bodies" ? "body" : "element") +
                                                              " named '" + item_name + "'" +
                                                              suggestion(item_name, names_in(document, {parts[0] == "bodies" ? "bodies" : "elements"}))));
  } else if (const std::vector<std::string> names = names_in(document, {"bodies", "elements"});
             parts.size() >= 3 && !document[parts[0]] && has_dotted_name(names)) {
    // <name>.<key> with a generated name (unitA.car2.body.mass) that no body or element has
    // (apply_instance_setting took those that one has), in a model with generated names.
    const std::string item_name = name_before_key(parts, 0);
    throw InputError(where + "the model has no body or element named '" + item_name + "'" + suggestion(item_name, names) +
                     "; a train's car's body or element is set as <train>.<car>.<name>.<key> (e.g. unitA.car2.body.mass=33000) "
                     "or bodies.<name>.<key>, elements.<name>.<key>");
  } else {
    throw InputError(where + (for_scaling ? no_number : "KEY must be a top-level key, section.key (e.g. simulation.rtol), "
                                                        "bodies.<name>.<key> or elements.<name>.<key>"));
  }
  for (std::size_t i = 0; i < indices.size(); ++i) {
    const YAML::Node list = node_at(root, path, path.size());
    std::string list_key = name;
    for (std::size_t j = 0; j < i; ++j) list_key += "[" + std::to_string(indices[j]) + "]";
    if (!list.IsSequence())
      throw InputError(where + "the model has no list at '" + list_key + "' (KEY[INDEX] names an entry of a list)");
    if (indices[i] >= list.size())
      throw InputError(where + "the list at '" + list_key + "' has " + std::to_string(list.size()) + " entries (index from 0)");
    path.push_back({"", indices[i]});
  }
  return path;
}

/// KEY*=FACTOR: multiplies an existing number of the model (a sensitivity run's +20 %). `label`
/// names the setting in messages; the scaled value is the setting's.
bool apply_scaling(YAML::Node& root, const std::string& setting, Reader& reader, const std::string& label) {
  const std::string where = label + ": ";
  const auto star = setting.find("*=");
  if (star == std::string::npos) return false;
  double factor = 0.0;
  try {
    factor = std::stod(setting.substr(star + 2));
  } catch (const std::exception&) {
    throw InputError(where + "expected KEY*=FACTOR with a number, e.g. elements.spring.stiffness*=1.2");
  }
  const std::string key = setting.substr(0, star);
  const std::vector<DocumentStep> path = setting_path(root, key, true, where);
  const YAML::Node number = node_at(root, path, path.size());
  if (!number || !number.IsScalar())
    throw InputError(where + "there is no number at '" + key +
                     "' to scale (KEY is section.key, bodies.<name>.<key> or elements.<name>.<key>, "
                     "optionally with [INDEX] for an entry of a list)");
  double value = 0.0;
  try {
    value = number.as<double>();
  } catch (const YAML::Exception&) {
    throw InputError(where + "'" + number.Scalar() + "' is not a number");
  }
  if (value == 0.0 && factor != 1.0)
    throw ZeroScaledError(where + "'" + key + "' is 0 in the model, so a factor changes nothing; "
                     "set a value with KEY=VALUE instead (or leave this parameter out)");
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", value * factor);
  const YAML::Node scaled(std::string{text});
  reader.add_override(scaled, label);
  put_value(root, path, scaled, reader, label);
  return true;
}

/// Applies one setting to the document: KEY=VALUE (simulation.t_end=1, bodies.<name>.<key>=...,
/// elements.<name>.<key>=..., gravity=[0,0], units=SI, bodies.cart.velocity[0]=-2) or
/// KEY*=FACTOR. The setting changes exactly the key it names (put_value). The value is
/// registered with the reader so that a bad value is reported against the setting rather than
/// a file line. `label`: how messages name the setting ("file: --set 'KEY=VALUE'" when empty).
void apply_override(YAML::Node& root, const std::string& setting, Reader& reader, std::string label = {}) {
  if (label.empty()) label = SourceLocation{reader.file(), 0}.prefix() + "--set '" + setting + "'";
  const std::string where = label + ": ";
  if (apply_scaling(root, setting, reader, label)) return;
  const auto equals = setting.find('=');
  if (equals == std::string::npos || equals == 0)
    throw InputError(where + "expected KEY=VALUE, e.g. simulation.t_end=0.5 or elements.spring.stiffness=200");
  const std::string key = setting.substr(0, equals);
  YAML::Node value;
  try {
    value = load_yaml_text(setting.substr(equals + 1), label);
  } catch (const YAML::Exception& e) {
    throw InputError(where + "the value is not valid YAML (" + e.msg + ")");
  } catch (const InputError& e) {
    // A --set value is one line: "--set 'KEY=VALUE':1:" would name a line of nothing.
    const std::string message = e.what(), numbered = label + ":1: ";
    throw InputError(message.rfind(numbered, 0) == 0 ? where + message.substr(numbered.size()) : message);
  }
  reader.add_override(value, label);
  put_value(root, setting_path(root, key, false, where), value, reader, label);
}

/// The crash codes' unit system: mm, tonne, s, N (mass in t = 1000 kg, stiffness in N/mm, stress in MPa).
constexpr const char* kMillimetreTonne = "mm-t-s-N";

const std::vector<std::string> kTopKeys = {"railcrash", "name", "units", "gravity", "bodies", "elements", "loads", "simulation", "description", "outputs",
                                           "responses", "scenario"};
const std::vector<std::string> kBodyKeys = {"name", "mass", "weight", "inertia", "position", "angle", "velocity", "angular_velocity",
                                            "car"};
const std::vector<std::string> kLoadKeys = {"type", "body", "at", "value"};
const std::vector<std::string> kPointKeys = {"body", "at"};
const std::vector<std::string> kOutputKeys = {"name", "body", "at", "quantities"};
const std::vector<std::string> kResponseKeys = {"crush_gauges", "crush", "reference_crush", "anticlimber", "vertical_yield_force",
                                                "reference_velocity", "vertical_force_window", "override_velocity_at",
                                                "collision_post_distance"};
const std::vector<std::string> kCrushGaugeKeys = {"name", "points"};
const std::vector<std::string> kVariantKeys = {"railcrash", "variant_of", "name", "description", "set"};
const std::vector<std::string> kSimulationKeys = {"t_end", "integrator", "rtol", "atol", "position_tolerance", "linear_ordering", "jacobian_kept_steps", "dt", "output_interval", "force_dt", "max_steps",
                                                  "static_equilibrium",
                                                  "penalty_stiffness", "penalty_damping", "penalty_rotational_stiffness",
                                                  "penalty_rotational_damping"};

Body read_body(const Reader& r, const YAML::Node& node, UnitSystem units, double gravity_magnitude) {
  r.require_map(node, "each body");
  const std::string name = r.name(r.required(node, "name", "body"), "body name");
  const std::string context = "body '" + name + "'";
  r.check_keys(node, kBodyKeys, context);
  Body b;
  b.name = name;
  b.where = r.at(node);
  if (node["mass"] && node["weight"]) r.fail(node["weight"], context + ": give either mass or weight, not both");
  if (node["weight"]) {
    if (units != UnitSystem::InLbfS)
      r.fail(node["weight"], context + ": 'weight' is for in-lbf-s models (weight in lbf); in " +
                                 std::string(r.scale().mass != 1.0 ? "mm-t-s-N give 'mass' in t" : "SI give 'mass' in kg"));
    const double weight = r.number(node["weight"], context + ": weight");
    if (!(weight > 0.0)) r.fail(node["weight"], context + ": weight must be positive (lbf)");
    b.mass = weight / gravity_magnitude;  // [lbf*s^2/in] = lbf / (386.088 in/s^2)
  } else {
    const YAML::Node mass = r.required(node, "mass", context + " (give mass" + std::string(units == UnitSystem::InLbfS ? " or weight" : "") + ")");
    b.mass = r.number(mass, context + ": mass");
    if (!(b.mass > 0.0)) r.fail(mass, context + ": mass must be positive");
    b.mass *= r.scale().mass;
  }
  const YAML::Node inertia = r.required(node, "inertia", context);
  b.inertia = r.number(inertia, context + ": inertia");
  if (b.inertia < 0.0) r.fail(inertia, context + ": inertia must not be negative (0 = point mass)");
  b.inertia *= r.scale().mass * r.scale().length * r.scale().length;
  const double length = r.scale().length;
  const auto position = r.numbers(r.required(node, "position", context), 2, context + ": position");
  b.x = position[0] * length;
  b.y = position[1] * length;
  if (node["angle"]) b.angle = r.number(node["angle"], context + ": angle");
  if (node["velocity"]) {
    const auto v = r.numbers(node["velocity"], 2, context + ": velocity");
    b.vx = v[0] * length;
    b.vy = v[1] * length;
  }
  if (node["angular_velocity"]) b.angular_velocity = r.number(node["angular_velocity"], context + ": angular_velocity");
  if (node["car"]) {  // the car's name heads its rows in summary.json, the run output and the report
    b.car = r.name(node["car"], context + ": car");
    if (b.car.front() == ' ' || b.car.back() == ' ')
      r.fail(node["car"], context + ": car '" + b.car + "' starts or ends with a space; write the car's name without them");
  }
  return b;
}

/// The index of the body `name` (read from `body_node`) names: kGround for ground, unless
/// `refuse_ground` says why the ground will not do here. An unknown name is refused with the
/// closest name and the names there are.
int body_index(const Reader& r, const YAML::Node& body_node, const std::string& name, const Model& model, const std::string& context,
               const char* refuse_ground = nullptr) {
  const auto index = model.find_body(name);
  if (!index) {
    std::vector<std::string> names;
    if (!refuse_ground) names.push_back("ground");
    for (const Body& b : model.bodies()) names.push_back(b.name);
    r.fail(body_node, context + ": unknown body '" + name + "'" + suggestion(name, names) + "; bodies are: " + join(names));
  }
  if (*index == kGround && refuse_ground) r.fail(body_node, context + ": " + refuse_ground);
  return *index;
}

/// A point's `at`: its offset [length] from the body's centre of mass, body frame.
std::pair<double, double> read_offset(const Reader& r, const YAML::Node& at, const std::string& context) {
  const auto xy = r.numbers(at, 2, context + ": at");
  return {xy[0] * r.scale().length, xy[1] * r.scale().length};
}

/// The body point of a map's `body` (a body's name, or ground unless `refuse_ground` says why
/// not) and `at` (default [0, 0]): an element's point, a crush gauge's, an output's.
PointRef read_body_point(const Reader& r, const YAML::Node& map, const Model& model, const std::string& context,
                         const char* refuse_ground = nullptr) {
  const YAML::Node body_node = r.required(map, "body", context);
  PointRef ref;
  ref.body = body_index(r, body_node, r.text(body_node, context + ": body"), model, context, refuse_ground);
  if (map["at"]) std::tie(ref.sx, ref.sy) = read_offset(r, map["at"], context);
  return ref;
}

/// A point map {body, at} of an element or a crush gauge.
PointRef read_point(const Reader& r, const YAML::Node& p, const Model& model, const std::string& context) {
  r.require_map(p, context);
  r.check_keys(p, kPointKeys, context);
  return read_body_point(r, p, model, context);
}

std::unique_ptr<Element> read_element(const Reader& r, const YAML::Node& node, const Model& model) {
  r.require_map(node, "each element");
  const std::string name = r.name(r.required(node, "name", "element"), "element name");
  const YAML::Node type_node = r.required(node, "type", "element '" + name + "'");
  const std::string type = r.text(type_node, "element '" + name + "': type");
  const ElementRegistry& registry = ElementRegistry::instance();
  const ElementType* element_type = registry.find(type);
  if (!element_type)
    r.fail(type_node, "element '" + name + "': unknown element type '" + type + "'" + suggestion(type, registry.types()) +
                          "; known types: " + join(registry.types()));
  const std::string context = "element '" + name + "' (" + type + ")";
  ElementSpec spec;
  spec.name = name;
  spec.type = type;
  spec.where = r.at(node);
  const YAML::Node points = r.required(node, "points", context);
  r.require_list(points, context + ": points");
  for (std::size_t i = 0; i < points.size(); ++i) {
    spec.points.push_back(read_point(r, points[i], model, context + ": point " + std::to_string(i + 1)));
  }
  if (spec.points.size() != element_type->points)
    throw InputError(spec.where.prefix() + context + " needs exactly " + std::to_string(element_type->points) +
                     (element_type->points == 1 ? " point" : " points") + ", found " +
                     std::to_string(spec.points.size()) + " (" + element_type->points_meaning + ")");
  // Keys first: a misspelt key would otherwise show up as a missing one.
  std::vector<std::string> allowed{"name", "type", "points"};
  for (const std::string& key : element_type->keys()) allowed.push_back(key);
  r.check_keys(node, allowed, context);
  YamlParameterReader parameters(*element_type, model.units, r, node, context);
  spec.parameters = &parameters;
  return element_type->factory(spec);
}

TimeTable read_load_value(const Reader& r, const YAML::Node& node, std::size_t width, const std::string& context) {
  TimeTable table;
  const auto read_value = [&](const YAML::Node& v, const std::string& what) -> std::array<double, 2> {
    if (width == 1) return {r.number(v, what), 0.0};
    const auto pair = r.numbers(v, 2, what);
    return {pair[0], pair[1]};
  };
  const bool tabulated = node.IsSequence() && node.size() > 0 && node[0].IsSequence();
  if (!tabulated) {
    table.times = {0.0};
    table.values = {read_value(node, context + ": value" + (width == 2 ? " [Fx, Fy]" : ""))};
    return table;
  }
  for (std::size_t i = 0; i < node.size(); ++i) {
    const YAML::Node row = node[i];
    const std::string what = context + ": table row " + std::to_string(i + 1);
    if (!row.IsSequence() || row.size() < 2)
      r.fail(row, what + " must be [t, value]" + std::string(width == 2 ? " with value [Fx, Fy] (or [t, Fx, Fy])" : ""));
    const double t = r.number(row[0], what + " time");
    std::array<double, 2> value{};
    if (width == 2 && row.size() == 3) {
      value = {r.number(row[1], what + " Fx"), r.number(row[2], what + " Fy")};
    } else if (row.size() == 2) {
      value = read_value(row[1], what + " value");
    } else {
      r.fail(row, what + " must be [t, value]");
    }
    if (!table.times.empty() && !(t > table.times.back()))
      r.fail(row[0], what + ": times must increase strictly down the table");
    table.times.push_back(t);
    table.values.push_back(value);
  }
  return table;
}

Load read_load(const Reader& r, const YAML::Node& node, const Model& model) {
  r.require_map(node, "each load");
  r.check_keys(node, kLoadKeys, "load");
  const std::string type = r.text(r.required(node, "type", "load"), "load type");
  const std::string body = r.text(r.required(node, "body", "load"), "load body");
  const std::string context = type + " load on '" + body + "'";
  Load load;
  load.where = r.at(node);
  if (type == "force") load.kind = Load::Kind::Force;
  else if (type == "moment") load.kind = Load::Kind::Moment;
  else r.fail(node["type"], "load: unknown type '" + type + "'; use force or moment");
  load.body = body_index(r, node["body"], body, model, context, "a load on the ground does nothing; name a body");
  if (node["at"]) {
    if (load.kind == Load::Kind::Moment) r.fail(node["at"], context + ": a moment has no point; remove 'at'");
    std::tie(load.sx, load.sy) = read_offset(r, node["at"], context);
  }
  load.value = read_load_value(r, r.required(node, "value", context), load.kind == Load::Kind::Force ? 2 : 1, context);
  const double unit = load.kind == Load::Kind::Force ? r.scale().force : r.scale().force * r.scale().length;
  for (auto& value : load.value.values)
    for (double& component : value) component *= unit;
  return load;
}

void read_outputs(const Reader& r, const YAML::Node& node, const Model& model, std::vector<OutputPoint>& output_points) {
  r.require_list(node, "outputs");
  std::vector<std::string> taken;  // names whose columns exist already
  for (const Body& b : model.bodies()) taken.push_back(b.name);
  for (const auto& e : model.elements()) taken.push_back(e->name());
  for (std::size_t i = 0; i < node.size(); ++i) {
    const YAML::Node item = node[i];
    const std::string context = "outputs: item " + std::to_string(i + 1);
    r.require_map(item, context);
    r.check_keys(item, kOutputKeys, context);
    OutputPoint output;
    output.where = r.at(item);
    output.point = read_body_point(r, item, model, context, "the ground does not move; name a body");
    const std::string body = item["body"].Scalar();
    const int index = output.point.body;
    if (item["name"]) {
      output.name = r.name(item["name"], context + ": name");
    } else {
      int k = 1;
      for (const OutputPoint& o : output_points) k += o.point.body == index;
      output.name = body + "_point" + std::to_string(k);
    }
    if (std::find(taken.begin(), taken.end(), output.name) != taken.end())
      r.fail(item["name"] ? item["name"] : item, context + ": the name '" + output.name +
                                                     "' is already a body, element or output; give the point another name");
    taken.push_back(output.name);
    if (item["quantities"]) {
      const YAML::Node list = item["quantities"];
      r.require_list(list, context + ": quantities");
      output.position = output.velocity = output.acceleration = false;
      for (std::size_t k = 0; k < list.size(); ++k) {
        const std::string q = r.text(list[k], context + ": quantity");
        if (q == "position") output.position = true;
        else if (q == "velocity") output.velocity = true;
        else if (q == "acceleration") output.acceleration = true;
        else r.fail(list[k], context + ": unknown quantity '" + q + "'; use position, velocity or acceleration");
      }
      if (list.size() == 0) r.fail(list, context + ": quantities is empty; list position, velocity and/or acceleration");
    }
    output_points.push_back(output);
  }
}

void read_responses(const Reader& r, const YAML::Node& node, const Model& model, ResponseSettings& s) {
  r.require_map(node, "responses");
  r.check_keys(node, kResponseKeys, "responses");
  if (node["crush_gauges"]) {
    r.require_list(node["crush_gauges"], "responses: crush_gauges");
    for (std::size_t i = 0; i < node["crush_gauges"].size(); ++i) {
      const YAML::Node g = node["crush_gauges"][i];
      const std::string context = "responses: crush gauge " + std::to_string(i + 1);
      r.require_map(g, context);
      r.check_keys(g, kCrushGaugeKeys, context);
      CrushGauge gauge;
      gauge.name = r.text(r.required(g, "name", context), context + ": name");
      if (const std::string problem = name_length_problem(context + ": name", gauge.name); !problem.empty()) r.fail(g["name"], problem);
      const YAML::Node points = r.required(g, "points", context);
      if (!points.IsSequence() || points.size() != 2) r.fail(points, context + ": points must be two points [{body, at}, {body, at}]");
      gauge.front = read_point(r, points[0], model, context + ": point 1");
      gauge.rear = read_point(r, points[1], model, context + ": point 2");
      s.crush_gauges.push_back(gauge);
    }
  }
  if (node["crush"]) {
    const std::string how = r.text(node["crush"], "responses: crush");
    if (how != "total" && how != "largest" && how != "anticlimber")
      r.fail(node["crush"], "responses: crush must be total or largest (of the crush gauges) or anticlimber");
    s.total_crush = how != "largest";
    s.crush_from_anticlimber = how == "anticlimber";
    if (s.crush_from_anticlimber && !node["anticlimber"])
      r.fail(node["crush"], "responses: crush: anticlimber needs 'anticlimber: <element name>'");
  }
  const auto positive = [&](const char* key) { return r.positive_key(node, key, "responses"); };
  if (!s.crush_gauges.empty() || s.crush_from_anticlimber) {
    if (!node["reference_crush"]) r.fail(node, "responses: crush gauges need 'reference_crush' (the maximum safe crush, R1 = crush / it)");
    s.reference_crush = *positive("reference_crush") * r.scale().length;
  }
  if (node["anticlimber"]) {
    s.anticlimber = r.text(node["anticlimber"], "responses: anticlimber");
    const auto& elements = model.elements();
    const auto it = std::find_if(elements.begin(), elements.end(), [&](const auto& e) { return e->name() == s.anticlimber; });
    if (it == elements.end() || !is_anticlimber_type((*it)->type()))
      r.fail(node["anticlimber"], "responses: 'anticlimber: " + s.anticlimber + "' must name an element of type anticlimber");
    s.vertical_yield_force = positive("vertical_yield_force");
    if (s.vertical_yield_force) *s.vertical_yield_force *= r.scale().force;
    if (node["vertical_force_window"]) {
      using Window = ResponseSettings::VerticalForceWindow;
      const std::string window = r.text(node["vertical_force_window"], "responses: vertical_force_window");
      if (window == "whole_run") s.vertical_force_window = Window::WholeRun;
      else if (window == "until_largest_crush") s.vertical_force_window = Window::UntilLargestCrush;
      else if (window == "until_separation") s.vertical_force_window = Window::UntilSeparation;
      else
        r.fail(node["vertical_force_window"],
               "responses: vertical_force_window must be whole_run, until_largest_crush or until_separation");
    }
    if (!node["reference_velocity"])
      r.fail(node, "responses: an anticlimber needs 'reference_velocity' (the velocity that fails the collision post, for R2 after override)");
    s.reference_velocity = *positive("reference_velocity") * r.scale().length;
    using At = ResponseSettings::OverrideVelocityAt;
    if (node["override_velocity_at"]) {
      const std::string at = r.text(node["override_velocity_at"], "responses: override_velocity_at");
      if (at == "collision_post") s.override_velocity_at = At::CollisionPost;
      else if (at == "override") s.override_velocity_at = At::Override;
      else
        r.fail(node["override_velocity_at"],
               "responses: override_velocity_at must be collision_post (when the overriding end sill reaches the other "
               "car's collision post, the report's) or override (at the override event)");
    }
    if (const auto distance = positive("collision_post_distance")) s.collision_post_distance = *distance * r.scale().length;
    else s.collision_post_distance = s.reference_crush;  // the report's words for both
    if (s.override_velocity_at == At::CollisionPost && !(s.collision_post_distance > 0.0))
      r.fail(node, "responses: R2 after an override takes the relative velocity when the overriding end sill reaches the "
                   "collision post: give 'collision_post_distance' (the anticlimber faces' approach from first touch at "
                   "which it does; default 'reference_crush') or 'override_velocity_at: override'");
  }
}

void read_simulation(const Reader& r, const YAML::Node& node, SimulationSettings& s) {
  r.require_map(node, "simulation");
  r.check_keys(node, kSimulationKeys, "simulation");
  const YAML::Node t_end = r.required(node, "t_end", "simulation");
  s.t_end = r.number(t_end, "simulation: t_end");
  if (!(s.t_end > 0.0)) r.fail(t_end, "simulation: t_end must be positive (the end time of the run)");
  if (node["integrator"]) {
    const std::string name = r.text(node["integrator"], "simulation: integrator");
    const std::optional<IntegratorKind> kind = integrator_from_name(name);
    if (!kind) r.fail(node["integrator"], "simulation: integrator must be " + integrator_names_text() + ", not '" + name + "'");
    s.integrator = *kind;
  }
  const auto positive = [&](const char* key) { return r.positive_key(node, key, "simulation"); };
  // A count of steps: a whole number of at least `least`; `what` says what it counts.
  const auto whole_steps = [&](const char* key, double least, const char* what) {
    const std::string name = std::string("simulation: ") + key;
    const double steps = r.number(node[key], name);
    if (!(steps >= least) || steps != std::floor(steps) || steps > 9.0e18) {
      std::ostringstream least_text;
      least_text << least;
      r.fail(node[key], name + " must be a whole number of at least " + least_text.str() + " (" + what + ")");
    }
    return static_cast<long>(steps);
  };
  if (node["rtol"]) {
    s.rtol = r.number(node["rtol"], "simulation: rtol");
    if (const std::string problem = rtol_problem(s.rtol, "simulation: rtol"); !problem.empty()) r.fail(node["rtol"], problem);
  }
  s.atol = positive("atol");
  const Reader::UnitScale& unit = r.scale();
  if (s.atol) *s.atol *= unit.length;
  if (node["position_tolerance"]) {
    const std::string how = r.text(node["position_tolerance"], "simulation: position_tolerance");
    if (how == "absolute") {
      s.position_tolerance = PositionTolerance::Absolute;
    } else if (how != "relative") {
      r.fail(node["position_tolerance"], "simulation: position_tolerance must be relative (rtol |q| + atol, the default) "
                                         "or absolute (atol alone, whatever the distance from the origin), not '" + how + "'");
    }
  }
  if (node["linear_ordering"]) {
    const std::string how = r.text(node["linear_ordering"], "simulation: linear_ordering");
    if (how == "amd") {
      s.linear_ordering = LinearOrdering::Amd;
    } else if (how == "colamd") {
      s.linear_ordering = LinearOrdering::Colamd;
    } else if (how != "fewest_entries") {
      r.fail(node["linear_ordering"], "simulation: linear_ordering must be fewest_entries (the default: AMD or COLAMD, "
                                      "whichever factors the first Newton matrix with fewer entries), amd or colamd, not '" +
                                          how + "'");
    }
  }
  if (node["jacobian_kept_steps"])
    s.jacobian_kept_steps = whole_steps("jacobian_kept_steps", 0.0, "the steps a Jacobian serves IDA's later setups; 0: one "
                                                                    "evaluated at every setup");
  if (auto v = positive("dt")) s.dt = *v;
  if (auto v = positive("output_interval")) s.output_interval = *v;
  const std::string rows_problem = output_rows_problem(s);
  if (!rows_problem.empty()) {  // named where it was set: the interval, or t_end when only that was overridden
    const YAML::Node interval = node["output_interval"];
    r.fail(interval && (r.overridden(interval) || !r.overridden(t_end)) ? interval : t_end, "simulation: " + rows_problem);
  }
  if (node["force_dt"]) s.force_dt = r.boolean(node["force_dt"], "simulation: force_dt");
  if (node["max_steps"]) s.max_steps = whole_steps("max_steps", 1.0, "the steps either integrator may take");
  if (node["static_equilibrium"])
    s.static_equilibrium = r.boolean(node["static_equilibrium"], "simulation: static_equilibrium");
  const auto scaled = [](std::optional<double> value, double factor) { return value ? std::optional<double>(*value * factor) : value; };
  s.penalty.stiffness = scaled(positive("penalty_stiffness"), unit.of(Unit::ForcePerLength));
  s.penalty.damping = scaled(positive("penalty_damping"), unit.of(Unit::ForceTimePerLength));
  s.penalty.rotational_stiffness = scaled(positive("penalty_rotational_stiffness"), unit.of(Unit::MomentPerAngle));
  s.penalty.rotational_damping = scaled(positive("penalty_rotational_damping"), unit.of(Unit::MomentTimePerAngle));
}

/// The last '[' or '{' still open at offset `end` of `text` (line 0 when none). Skips
/// comments, quoted strings and block scalars (| and >); outside flow collections only a
/// bracket that starts a value counts (a plain scalar may contain brackets).
struct OpenBracket {
  int line = 0;
  char bracket = 0;
};

OpenBracket unclosed_bracket(const std::string& text, std::size_t end) {
  std::vector<OpenBracket> open;
  end = std::min(end, text.size());
  char quote = 0;
  int block_indent = -1;  // >= 0: inside a block scalar whose key line has this indentation
  int line = 0;
  for (std::size_t start = 0; start < end;) {
    std::size_t stop = text.find('\n', start);
    if (stop == std::string::npos) stop = text.size();
    ++line;
    const std::size_t first = text.find_first_not_of(" ", start);
    const int indent = static_cast<int>((first == std::string::npos ? stop : std::min(first, stop)) - start);
    const bool blank = first == std::string::npos || first >= stop || text[first] == '\r';
    if (block_indent >= 0 && (blank || indent > block_indent)) {
      start = stop + 1;
      continue;
    }
    block_indent = -1;
    char previous = '\n';  // last non-blank character outside quotes on this line
    std::size_t content_end = stop;
    for (std::size_t i = start; i < std::min(stop, end); ++i) {
      const char c = text[i];
      if (quote) {
        if (c == quote && !(quote == '"' && i > start && text[i - 1] == '\\')) quote = 0;
        continue;
      }
      if (c == '#' && (i == start || text[i - 1] == ' ' || text[i - 1] == '\t')) {
        content_end = i;
        break;
      }
      const bool value_start = previous == '\n' || previous == ':' || previous == '-' || previous == ',' ||
                               previous == '[' || previous == '{' || previous == '?';
      if ((c == '\'' || c == '"') && value_start) {
        quote = c;
      } else if ((c == '[' || c == '{') && (value_start || !open.empty())) {
        open.push_back({line, c});
      } else if ((c == ']' || c == '}') && !open.empty()) {
        open.pop_back();
      }
      if (c != ' ' && c != '\t' && c != '\r') previous = c;
    }
    if (!quote && open.empty()) {  // "key: |" or "- >-" starts a block scalar on the next lines
      std::size_t last = content_end;
      while (last > start && (text[last - 1] == ' ' || text[last - 1] == '\t' || text[last - 1] == '\r')) --last;
      std::size_t word = last;
      while (word > start && text[word - 1] != ' ') --word;
      if (word < last && (text[word] == '|' || text[word] == '>') &&
          text.find_first_not_of("+-0123456789", word + 1) >= last && word > start)
        block_indent = indent;
    }
    start = stop + 1;
  }
  return open.empty() ? OpenBracket{} : open.back();
}

ScenarioSectionReader& scenario_section_reader() {
  static ScenarioSectionReader reader = nullptr;  // a function's static: set from another file's static initialiser
  return reader;
}

LoadedModel build(const YAML::Node& root, Reader& r) {
  if (!root.IsMap()) r.fail(root, "a model file must be a YAML map with keys railcrash, name, units, bodies, elements, simulation");
  r.check_keys(root, kTopKeys, "model");
  LoadedModel loaded;
  Model& model = loaded.model;
  RunSpec& run_spec = loaded.run_spec;
  model.file = r.file();
  const YAML::Node version = r.required(root, "railcrash", "model (format version: add 'railcrash: 1')");
  if (r.number(version, "railcrash (format version)") != 1.0)
    r.fail(version, "this railcrash reads model format 1; found railcrash: " + version.Scalar());
  model.name = r.text(r.required(root, "name", "model"), "name");
  if (const std::string problem = name_length_problem("the model's name", model.name); !problem.empty()) r.fail(root["name"], problem);
  const YAML::Node units = r.required(root, "units", "model");
  const std::string unit_name = r.text(units, "units");
  if (unit_name == "SI") {
    model.units = UnitSystem::SI;
  } else if (unit_name == "in-lbf-s") {
    model.units = UnitSystem::InLbfS;
  } else if (unit_name == kMillimetreTonne) {  // mm, t (1000 kg), s, N: converted to SI here, once
    model.units = UnitSystem::SI;
    r.set_scale({1.0e-3, 1.0e3, 1.0});
  } else {
    r.fail(units, "units must be SI or in-lbf-s, not '" + unit_name + "' (or " + kMillimetreTonne + ": mm, tonne, s, N)");
  }
  model.file_units = unit_name;
  const double g = standard_gravity(model.units);
  model.gravity_x = 0.0;
  model.gravity_y = -g;
  if (root["gravity"]) {
    const auto gravity = r.numbers(root["gravity"], 2, "gravity");
    model.gravity_x = gravity[0] * r.scale().length;
    model.gravity_y = gravity[1] * r.scale().length;
  }
  const YAML::Node bodies = r.required(root, "bodies", "model");
  r.require_list(bodies, "bodies");
  if (bodies.size() == 0) r.fail(bodies, "bodies: the list is empty; add at least one body");
  for (std::size_t i = 0; i < bodies.size(); ++i) model.add_body(read_body(r, bodies[i], model.units, g));
  if (root["elements"]) {
    r.require_list(root["elements"], "elements");
    for (std::size_t i = 0; i < root["elements"].size(); ++i) model.add_element(read_element(r, root["elements"][i], model));
  }
  if (root["loads"]) {
    r.require_list(root["loads"], "loads");
    for (std::size_t i = 0; i < root["loads"].size(); ++i) model.add_load(read_load(r, root["loads"][i], model));
  }
  if (root["responses"]) read_responses(r, root["responses"], model, run_spec.responses);
  if (root["outputs"]) read_outputs(r, root["outputs"], model, run_spec.output_points);
  if (root["scenario"]) {
    if (!scenario_section_reader())
      r.fail(root["scenario"], "scenario: this program reads no scenario sections (the scenario layer is not linked in); remove the section");
    run_spec.scenario = scenario_section_reader()(root["scenario"], model, r.scale().length,
                                                  [&r](const YAML::Node& node, const std::string& message) { r.fail(node, message); });
  }
  read_simulation(r, r.required(root, "simulation", "model (add a simulation section with at least t_end)"), run_spec.simulation);
  return loaded;
}

}  // namespace

namespace {

/// parse(), which reads `text` as YAML, with its parse errors as InputErrors that say where
/// (and which bracket was left open).
template <class Parse>
auto with_model_parse_errors(const std::string& text, const std::string& path, const Parse& parse) {
  try {
    return parse();
  } catch (const YAML::ParserException& e) {
    const int line = e.mark.is_null() ? 0 : e.mark.line + 1;
    // A ']' or '}' left out is noticed only where the next thing starts (often the next
    // line, as "end of sequence flow not found" or "illegal block entry"): point at the
    // bracket that was left open.
    const OpenBracket open = unclosed_bracket(text, e.mark.is_null() ? text.size() : static_cast<std::size_t>(e.mark.pos));
    const bool flow_end = e.msg == YAML::ErrorMsg::END_OF_SEQ_FLOW || e.msg == YAML::ErrorMsg::END_OF_MAP_FLOW;
    if (open.line > 0 && (flow_end || (e.msg == YAML::ErrorMsg::BLOCK_ENTRY && open.line < line)))
      throw InputError(SourceLocation{path, open.line}.prefix() + "not valid YAML: the '" + std::string(1, open.bracket) +
                       "' on this line is never closed; add the matching '" + (open.bracket == '[' ? "]" : "}") +
                       "' (the parser stopped at line " + std::to_string(line) + ": " + e.msg + ")");
    throw InputError(SourceLocation{path, line}.prefix() + "not valid YAML: " + e.msg);
  }
}

YAML::Node parse_model_yaml(const std::string& text, const std::string& path) {
  return with_model_parse_errors(text, path, [&] { return load_yaml_text(text, path); });
}

/// The base model a variant at `path` names (`variant_of`, relative to the variant's folder).
std::filesystem::path variant_base_path(const std::string& path, const std::string& base_name) {
  return std::filesystem::path(base_name).is_absolute() ? std::filesystem::path(base_name)
                                                        : std::filesystem::path(path).parent_path() / base_name;
}

/// A setting taken from a variant file: KEY=VALUE and how messages name it.
struct VariantSetting {
  std::string setting, label;
};

/// A variant file (README "Model variants"): `variant_of: BASE` (relative to the variant's
/// folder), an optional `name` and `description`, and `set:` a map KEY: VALUE of the same keys
/// as --set. Returns the base document; `file` becomes the base file (its lines are the
/// base's), `settings` the variant's changes, to be applied like --set before the user's own.
YAML::Node resolve_variant(const YAML::Node& variant, const std::string& path, std::string& file,
                           std::vector<VariantSetting>& settings, std::vector<ModelSource>& sources) {
  const Reader reader(path);
  reader.check_keys(variant, kVariantKeys, "model variant");
  const YAML::Node version = reader.required(variant, "railcrash", "model variant (add 'railcrash: 1')");
  if (!version.IsScalar() || version.Scalar() != "1") reader.fail(version, "model variant: 'railcrash' must be 1");
  const YAML::Node base_node = variant["variant_of"];
  const std::filesystem::path base_path = variant_base_path(path, reader.text(base_node, "model variant: variant_of"));
  std::string base_text;
  try {
    base_text = read_input_file(base_path.string(), "base model");
  } catch (const InputError& e) {
    reader.fail(base_node, "model variant: variant_of (relative to the variant's folder): " + std::string(e.what()));
  }
  file = base_path.string();
  sources.push_back({file, sha256_hex(base_text)});
  YAML::Node base = parse_model_yaml(base_text, file);
  if (base.IsMap() && base["variant_of"])
    reader.fail(base_node, "model variant: '" + file + "' is itself a variant; name the model it is a variant of");
  const auto add = [&](const YAML::Node& key, const std::string& name, const YAML::Node& value) {
    const std::string label = reader.at(key).prefix() + "set '" + name + "'";
    if (!value.IsDefined() || value.IsNull()) throw InputError(label + ": give a value (" + name + ": VALUE)");
    settings.push_back({name + "=" + YAML::Dump(value), label});
  };
  for (const char* key : {"name", "description"})
    if (variant[key]) add(variant[key], key, variant[key]);
  if (variant["set"]) {
    reader.require_map(variant["set"], "model variant: set");
    for (const auto& entry : variant["set"]) {
      if (!entry.first.IsScalar()) reader.fail(entry.first, "model variant: set: keys are KEY paths like elements.spring.stiffness");
      add(entry.first, entry.first.Scalar(), entry.second);
    }
  }
  return base;
}

}  // namespace

namespace {

/// The settings in the order they apply (the variant's, --set's, the options'), each with its
/// label ("" for --set: apply_override names it).
std::vector<VariantSetting> all_settings(const std::vector<VariantSetting>& variant_settings, const std::vector<std::string>& overrides,
                                         const std::vector<OptionSetting>& options, const std::string& file) {
  std::vector<VariantSetting> settings = variant_settings;
  for (const auto& setting : overrides) settings.push_back({setting, ""});
  for (const OptionSetting& o : options) settings.push_back({o.setting, SourceLocation{file, 0}.prefix() + o.option});
  return settings;
}

/// Applies the settings to the document: those on car types and trains first, then the
/// expansion into flat bodies and elements (train_expansion.hpp), then the others (on
/// generated names too: unitA.car3.front_crush.stiffness=...).
void apply_settings(YAML::Node& root, const std::vector<VariantSetting>& settings, Reader& reader, TrainExpansion& expansion) {
  const MarkSetting mark = [&reader](const YAML::Node& node, const std::string& label) { reader.add_override(node, label); };
  const auto label = [&reader](const VariantSetting& s) {
    return s.label.empty() ? SourceLocation{reader.file(), 0}.prefix() + "--set '" + s.setting + "'" : s.label;
  };
  for (const VariantSetting& s : settings)
    if (is_train_definition_setting(s.setting)) apply_train_definition_setting(root, s.setting, label(s), mark);
  expand_trains(root, reader.file(), expansion, [&reader](const YAML::Node& node) { return reader.setting_of(node); }, mark);
  reader.set_expansion(&expansion);
  for (const VariantSetting& s : settings)
    if (!is_train_definition_setting(s.setting) && !(expansion.expanded && apply_instance_setting(root, s.setting, label(s), mark)))
      apply_override(root, s.setting, reader, s.label);
}

/// The model of a parsed model file (`root`, the text `text` read from `path`), with the settings applied.
LoadedModel model_from_yaml(YAML::Node root, const std::string& text, const std::string& path, const std::vector<std::string>& overrides,
                      const std::vector<OptionSetting>& options) {
  std::string file = path;
  std::vector<VariantSetting> variant_settings;
  std::vector<ModelSource> sources{{path, sha256_hex(text)}};
  if (root.IsMap() && root["variant_of"]) root = resolve_variant(root, path, file, variant_settings, sources);
  Reader reader(file);
  reader.index_empty_values(root);
  TrainExpansion expansion;
  if (root.IsMap() || root.IsNull())  // otherwise build() says what the file should look like
    apply_settings(root, all_settings(variant_settings, overrides, options, reader.file()), reader, expansion);
  try {
    LoadedModel loaded = build(root, reader);
    Model& model = loaded.model;
    model.sources = std::move(sources);
    model.settings = overrides;
    for (const OptionSetting& o : options) model.settings.push_back(o.setting);
    model.finalize();
    return loaded;
  } catch (const YAML::Exception& e) {  // a check above missed a case: still an input error with a line
    throw InputError(SourceLocation{file, e.mark.is_null() ? 0 : e.mark.line + 1}.prefix() + "cannot read the model: " + e.msg);
  }
}

}  // namespace

LoadedModel load_model_text(const std::string& text, const std::string& path, const std::vector<std::string>& overrides,
                            const std::vector<OptionSetting>& options) {
  return model_from_yaml(parse_model_yaml(text, path), text, path, overrides, options);
}

CheckedYamlText check_model_text(std::string text, const std::string& path) {
  // A copy goes into the checked text: a parse error's message reads `text` (the open bracket).
  return with_model_parse_errors(text, path, [&] { return CheckedYamlText(text, path); });
}

std::vector<std::string> model_input_texts(const std::string& text, const std::string& path) {
  std::vector<std::string> texts{text};
  const YAML::Node root = parse_model_yaml(text, path);
  if (root.IsMap() && root["variant_of"] && root["variant_of"].IsScalar())
    texts.push_back(read_input_file(variant_base_path(path, root["variant_of"].Scalar()).string(), "base model"));
  return texts;
}

LoadedModel load_model_text(const CheckedYamlText& text, const std::string& path, const std::vector<std::string>& overrides) {
  // Checked when it was read; a parse error here would have been found then.
  return model_from_yaml(load_yaml_text(text), text.text(), path, overrides, {});
}

LoadedModel load_model_text(const std::string& text, const std::string& path, const std::vector<std::string>& overrides) {
  return load_model_text(text, path, overrides, {});
}

LoadedModel load_model(const std::string& path, const std::vector<std::string>& overrides) {
  return load_model_text(read_input_file(path, "model file"), path, overrides, {});
}

LoadedModel load_model(const std::string& path, const std::vector<std::string>& overrides, const std::vector<OptionSetting>& options) {
  return load_model_text(read_input_file(path, "model file"), path, overrides, options);
}

LoadedModel load_model(const std::string& path) { return load_model(path, {}); }

ExpandedModel expand_model_file(const std::string& path, const std::vector<std::string>& overrides) {
  const std::string text = read_input_file(path, "model file");
  YAML::Node root = parse_model_yaml(text, path);
  std::string file = path;
  std::vector<VariantSetting> variant_settings;
  std::vector<ModelSource> sources;  // (not written out: the expanded text is the model itself)
  if (root.IsMap() && root["variant_of"]) root = resolve_variant(root, path, file, variant_settings, sources);
  Reader reader(file);
  reader.index_empty_values(root);
  TrainExpansion expansion;
  if (root.IsMap()) apply_settings(root, all_settings(variant_settings, overrides, {}, reader.file()), reader, expansion);
  ExpandedModel out;
  out.cars = expansion.cars;
  YAML::Emitter emitter;
  emitter << unshared_copy(root);  // (the expansion shares keys: no anchors in the text)
  out.text = "# " + path + " with its car types and trains expanded (railcrash expand)\n" + std::string(emitter.c_str()) + "\n";
  return out;
}

double file_length_unit(const Model& model) { return model.file_units == kMillimetreTonne ? 1.0e-3 : 1.0; }

bool set_scenario_section_reader(ScenarioSectionReader reader) {
  scenario_section_reader() = reader;
  return true;
}

std::vector<std::string> model_file_keys() {
  std::vector<std::string> keys;
  for (const auto* list : {&kTopKeys, &kBodyKeys, &kLoadKeys, &kSimulationKeys, &kPointKeys, &kOutputKeys, &kResponseKeys,
                           &kCrushGaugeKeys, &kVariantKeys, &train_expansion_keys()})
    for (const std::string& key : *list)
      if (std::find(keys.begin(), keys.end(), key) == keys.end()) keys.push_back(key);
  return keys;
}

std::vector<std::pair<std::string, std::vector<std::string>>> model_file_sections() {
  return {{"model", kTopKeys},          {"body", kBodyKeys},         {"point", kPointKeys},
          {"load", kLoadKeys},          {"simulation", kSimulationKeys}, {"output", kOutputKeys},
          {"responses", kResponseKeys}, {"crush_gauge", kCrushGaugeKeys}, {"variant", kVariantKeys}};
}

}  // namespace railcrash
