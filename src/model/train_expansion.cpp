// Car types and trains expanded into flat bodies and elements (train_expansion.hpp).
#include "railcrash/model/train_expansion.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <set>
#include <sstream>
#include <unordered_set>

#include "railcrash/core/error.hpp"
#include "railcrash/model/element_registry.hpp"
#include "railcrash/model/model_io.hpp"
#include "railcrash/model/yaml_file.hpp"
#include "railcrash/model/yaml_reader.hpp"

namespace railcrash {

// ---- TrainExpansion ---------------------------------------------------------------------------
// A node is known by the address of its data (Node::Scalar() is a reference into it, for every
// kind of node): yaml-cpp gives no other identity that can be ordered. Setting a scalar keeps
// its data. The origins are collected in a list and sorted once (seal): a hash map of them cost
// twice the rest of the expansion of 200 cars (bench: railcrash_bench trains).

const TrainExpansion::Origin* TrainExpansion::origin(const YAML::Node& node) const {
  if (origins_.empty() || !node.IsDefined()) return nullptr;
  const void* key = &node.Scalar();
  const auto it = std::lower_bound(origins_.begin(), origins_.end(), key,
                                   [](const std::pair<const void*, Origin>& entry, const void* k) { return entry.first < k; });
  return it == origins_.end() || it->first != key ? nullptr : &it->second;
}

void TrainExpansion::add(const YAML::Node& node, int line, const std::string* note) {
  origins_.emplace_back(&node.Scalar(), Origin{line, note});
}

void TrainExpansion::seal() {
  // (stable: a node registered twice keeps its last origin; in place, no second list)
  std::stable_sort(origins_.begin(), origins_.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::size_t kept = 0;
  for (std::size_t k = 0; k < origins_.size(); ++k) {
    if (kept > 0 && origins_[kept - 1].first == origins_[k].first) origins_[kept - 1] = origins_[k];
    else origins_[kept++] = origins_[k];
  }
  origins_.resize(kept);
}

const std::string* TrainExpansion::note(std::string text) {
  notes_.push_back(std::make_unique<std::string>(std::move(text)));
  return notes_.back().get();
}

const std::vector<std::string>& train_expansion_keys() {
  static const std::vector<std::string> keys = {"car_types", "interface_types", "trains", "connections", "interfaces", "front",
                                                "rear", "facing", "speed", "coupling", "couplings", "cars", "reversed", "gap",
                                                "end", "ends"};
  return keys;
}

namespace {

const std::vector<std::string> kDefinitionSections = {"car_types", "interface_types", "trains", "connections"};
const std::vector<std::string> kCarTypeKeys = {"description", "bodies", "elements", "interfaces"};
const std::vector<std::string> kInterfaceTypeKeys = {"description", "elements"};
const std::vector<std::string> kInterfaceKeys = {"body", "at"};
const std::vector<std::string> kTrainKeys = {"name", "description", "front", "facing", "speed", "coupling", "couplings", "cars"};
const std::vector<std::string> kCarKeys = {"type", "name", "reversed"};
const std::vector<std::string> kCouplingKeys = {"type", "gap"};
const std::vector<std::string> kConnectionKeys = {"name", "type", "ends"};
const std::vector<std::string> kEndPointKeys = {"end", "at"};

std::string join(const std::vector<std::string>& words) { return join_words(words); }

/// Shortest text that reads back as the same double.
std::string number_text(double value) {
  if (value == 0.0) value = 0.0;  // no "-0"
  char text[40];
  for (int digits = 15; digits <= 17; ++digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, value);
    if (std::strtod(text, nullptr) == value) break;
  }
  return text;
}

std::vector<std::string> split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::stringstream stream(text);
  for (std::string part; std::getline(stream, part, separator);) parts.push_back(part);
  return parts;
}

/// Reads the definitions with messages "file:line: ..." (the shared checks: YamlReader). Its
/// number, pair and word keep their own wording (the model reader's number adds "(it is empty)"
/// and the text of a non-finite value; its pairs are "[a, b]" with entries "entry 1").
class Checker : public YamlReader {
 public:
  explicit Checker(const std::string& file) : YamlReader(file) {}
  double number(const YAML::Node& node, const std::string& what) const {
    double value = 0.0;
    try {
      if (!node.IsScalar()) fail(node, what + " must be a number");
      value = node.as<double>();
    } catch (const YAML::Exception&) {
      fail(node, what + " must be a number, not '" + node.Scalar() + "'");
    }
    if (!std::isfinite(value)) fail(node, what + " must be a finite number");
    return value;
  }
  std::array<double, 2> pair(const YAML::Node& node, const std::string& what) const {
    if (!node.IsSequence() || node.size() != 2) fail(node, what + " must be a list of 2 numbers [x, y]");
    return {number(node[0], what + " x"), number(node[1], what + " y")};
  }
  std::string word(const YAML::Node& node, const std::string& what) const {
    if (!node.IsScalar() || node.Scalar().empty()) fail(node, what + " must be a word");
    if (const std::string problem = name_length_problem(what, node.Scalar()); !problem.empty()) fail(node, problem);
    return node.Scalar();
  }
};

/// A placement of car coordinates: global x = anchor + mirror * x, y unchanged.
struct Placement {
  double anchor = 0.0;  // [length]
  double mirror = 1.0;  // +1 or -1
  double x(double car_x) const { return anchor + mirror * car_x; }
};

/// Copies nodes (new nodes, each registered with the line of the text it copies and the
/// instance's note) and edits the copies.
class Editor {
 public:
  /// `document`: the document the copies join. Its nodes move into the pool's memory now, while
  /// it holds few, so that joining the generated lists to it later merges nothing (yaml-cpp
  /// merges two memories by inserting every node of one into the other's set: for 200 cars,
  /// 85,000 nodes, a third of the expansion's time).
  Editor(YAML::Node& document, TrainExpansion& expansion, const SettingOf& setting_of, const MarkSetting& mark)
      : expansion_(expansion), setting_of_(setting_of), mark_(mark) {
    pool_.push_back(document);  // (the pool is never emitted: its items are only the copies' memory)
    pooled_ = 1;
  }

  const std::string* note = nullptr;  // the instance the copies belong to

  /// A new, empty node (null until given a scalar, items or entries). Every node the expansion
  /// makes lives in one yaml-cpp memory (the pool's): a node made on its own (YAML::Node(...))
  /// has its own, and joining memories copies their sets of nodes, which for 200 cars cost
  /// most of the expansion's time.
  YAML::Node make(YAML::EmitterStyle::value style = YAML::EmitterStyle::Default) {
    YAML::Node node = pool_[pooled_++];
    node.SetStyle(style);  // (also makes it defined: the pool's next item needs that)
    return node;
  }
  YAML::Node scalar(const std::string& text, int line) {
    YAML::Node node = make();
    node = text;
    expansion_.add(node, line, note);
    return node;
  }

  YAML::Node copy(const YAML::Node& node, int fallback_line, bool inside_setting = false) {
    const int line = node.Mark().is_null() ? fallback_line : node.Mark().line + 1;
    YAML::Node out = make(node.Style());
    if (node.IsScalar()) {
      out = node.Scalar();
      if (!node.Tag().empty()) out.SetTag(node.Tag());
    } else if (node.IsSequence()) {
      for (const YAML::Node& item : node) out.push_back(copy(item, line, inside_setting || setting_of_(node)));
    } else if (node.IsMap()) {
      const bool set = inside_setting || setting_of_(node);
      for (const auto& entry : node)
        out.force_insert(shared_key(entry.first, line, set), copy(entry.second, yaml_line(entry.first) ? yaml_line(entry.first) : line, set));
    }
    expansion_.add(out, line, note);
    if (!inside_setting)
      if (const std::string* setting = setting_of_(node)) mark_(out, *setting);
    return out;
  }

  /// A map's key for a copy: the key itself, shared by every copy of its map, since nothing edits
  /// a key in place (a third of a car's nodes are keys: copying them was a third of the
  /// expansion's time). Its origin is registered once, with the instance that copied it first:
  /// a key's error (unknown, given twice) is the same in every instance, and the loader reads the
  /// instances in the order they were placed, so it meets it in that one. An emitter would write
  /// shared nodes as anchors and aliases: the expanded text is written from unshared_copy().
  YAML::Node shared_key(const YAML::Node& key, int fallback_line, bool inside_setting) {
    if (!key.IsScalar()) return copy(key, fallback_line, inside_setting);
    if (registered_keys_.insert(&key.Scalar()).second) expansion_.add(key, yaml_line(key) ? yaml_line(key) : fallback_line, note);
    return key;
  }

  /// A node the expansion made (the pool's), at `line`.
  YAML::Node fresh(const YAML::Node& value, int line) {
    expansion_.add(value, line, note);
    return value;
  }
  YAML::Node fresh_pair(double a, double b, int line) {
    YAML::Node pair = make(YAML::EmitterStyle::Flow);
    pair.push_back(scalar(number_text(a), line));
    pair.push_back(scalar(number_text(b), line));
    return fresh(pair, line);
  }
  /// Adds `key: value` to the map `map` (a copy without that key).
  void insert(YAML::Node& map, const std::string& key, const YAML::Node& value, int line) { map.force_insert(scalar(key, line), value); }

  /// Sets the scalar `node` (a copy) to `text`, keeping its origin.
  void set(YAML::Node node, const std::string& text) {
    node = text;  // in place: the node keeps its origin, and a setting's label still names it
  }
  void set(YAML::Node node, double value) { set(node, number_text(value)); }

 private:
  YAML::Node pool_{YAML::NodeType::Sequence};
  std::size_t pooled_ = 0;
  std::unordered_set<const void*> registered_keys_;  // the shared keys (by their data) whose origin is registered
  TrainExpansion& expansion_;
  const SettingOf& setting_of_;
  const MarkSetting& mark_;
};

struct CarEnd {
  std::string body;  // generated body name
  double sx = 0.0, sy = 0.0;  // [length] offset from the body's centre, body frame (global axes at the start)
  double x = 0.0, y = 0.0;    // [length] global position
  YAML::Node where;           // the instance's node (for messages)
};

struct CarInstance {
  std::string name;  // <train>.<car>
  CarEnd leading, trailing, front, rear;
};

/// One car type, read once.
struct CarType {
  std::string name;
  YAML::Node node;
  int line = 0;  // of its name
  std::vector<std::string> body_names;
  struct Interface {
    std::string body;
    double x = 0.0, y = 0.0;    // [length] car coordinates
    double sx = 0.0, sy = 0.0;  // [length] body-frame offset
  } front, rear;
};

class Expander {
 public:
  Expander(YAML::Node& root, const std::string& file, TrainExpansion& expansion, const SettingOf& setting_of,
           const MarkSetting& mark)
      : root_(root), doc_(root), check_(file), expansion_(expansion), edit_(root, expansion, setting_of, mark) {}

  void run() {
    if (doc_["car_types"]) read_car_types(doc_["car_types"]);
    if (doc_["interface_types"]) {
      check_.require_map(doc_["interface_types"], "interface_types");
      for (const auto& entry : doc_["interface_types"]) {
        check_.check_map_keys(entry.second, kInterfaceTypeKeys, "interface type '" + entry.first.Scalar() + "'");
        interface_types_[entry.first.Scalar()] = entry.second;
        interface_type_lines_[entry.first.Scalar()] = yaml_line(entry.first);
      }
    }
    if (doc_["trains"]) {
      check_.require_list(doc_["trains"], "trains");
      for (const YAML::Node& train : doc_["trains"]) read_train(train);
    } else if (doc_["car_types"]) {
      check_.fail(doc_["car_types"], "car_types: no train places these cars; add a 'trains:' list (README \"Car types and trains\")");
    }
    if (doc_["connections"]) {
      check_.require_list(doc_["connections"], "connections");
      for (const YAML::Node& connection : doc_["connections"]) read_connection(connection);
    }
    // The flat model: generated bodies and elements first, then the file's own.
    for (const char* section : {"bodies", "elements"}) {
      YAML::Node& generated = std::string(section) == "bodies" ? bodies_ : elements_;
      if (doc_[section]) {
        check_.require_list(doc_[section], section);
        for (const YAML::Node& item : doc_[section]) generated.push_back(item);
      }
      root_[section] = generated;
    }
    for (const std::string& key : kDefinitionSections) root_.remove(key);
    expansion_.seal();
    expansion_.expanded = true;
  }

 private:
  void read_car_types(const YAML::Node& types) {
    check_.require_map(types, "car_types");
    for (const auto& entry : types) {
      CarType type;
      type.name = check_.word(entry.first, "car type name");
      type.node = entry.second;
      type.line = yaml_line(entry.first);
      const std::string what = "car type '" + type.name + "'";
      check_.check_map_keys(type.node, kCarTypeKeys, what);
      const YAML::Node bodies = check_.required(type.node, "bodies", what);
      check_.require_list(bodies, what + ": bodies");
      std::map<std::string, YAML::Node> body_nodes;
      for (const YAML::Node& b : bodies) {
        check_.require_map(b, what + ": each body");
        const std::string name = check_.word(check_.required(b, "name", what + ": body"), what + ": body name");
        if (body_nodes.count(name)) check_.fail(b["name"], what + ": two bodies are named '" + name + "'");
        body_nodes[name] = b;
        type.body_names.push_back(name);
      }
      if (type.node["elements"]) check_.require_list(type.node["elements"], what + ": elements");
      const YAML::Node interfaces = check_.required(type.node, "interfaces", what + " (its front and rear ends)");
      check_.check_map_keys(interfaces, {"front", "rear"}, what + ": interfaces");
      for (const char* end : {"front", "rear"}) {
        const YAML::Node i = check_.required(interfaces, end, what + ": interfaces");
        const std::string iw = what + ": interface " + end;
        check_.check_map_keys(i, kInterfaceKeys, iw);
        CarType::Interface& out = std::string(end) == "front" ? type.front : type.rear;
        const YAML::Node body_node = check_.required(i, "body", iw);
        out.body = check_.word(body_node, iw + ": body");
        const auto body = body_nodes.find(out.body);
        if (body == body_nodes.end())
          check_.fail(body_node, iw + ": no body '" + out.body + "' in the car type" + suggestion(out.body, type.body_names) +
                                     "; its bodies are: " + join(type.body_names));
        if (i["at"]) {
          const auto at = check_.pair(i["at"], iw + ": at");
          out.sx = at[0];
          out.sy = at[1];
        }
        const auto position = check_.pair(check_.required(body->second, "position", what + ": body '" + out.body + "'"),
                                          what + ": body '" + out.body + "': position");
        const double angle = body->second["angle"] ? check_.number(body->second["angle"], what + ": angle") : 0.0;
        if (angle != 0.0)
          check_.fail(body->second["angle"], iw + ": the interface's body '" + out.body +
                                                 "' starts rotated; an interface body must start level (angle 0)");
        out.x = position[0] + out.sx;
        out.y = position[1] + out.sy;
      }
      if (!(type.front.x > type.rear.x))
        check_.fail(interfaces, what + ": the front interface must lie ahead of the rear one (larger x in the car's coordinates)");
      car_types_.push_back(type);
    }
  }

  const CarType& car_type(const YAML::Node& node, const std::string& what) {
    const std::string name = check_.word(node, what);
    std::vector<std::string> names;
    for (const CarType& t : car_types_) {
      if (t.name == name) return t;
      names.push_back(t.name);
    }
    check_.fail(node, what + ": no car type '" + name + "'" + suggestion(name, names) +
                          (names.empty() ? "; the model has no car_types" : "; car types: " + join(names)));
  }

  /// The interface type `node` names, and its name.
  std::pair<YAML::Node, std::string> interface_type(const YAML::Node& node, const std::string& what) {
    const std::string name = check_.word(node, what);
    const auto it = interface_types_.find(name);
    if (it != interface_types_.end()) return {it->second, name};
    std::vector<std::string> names;
    for (const auto& entry : interface_types_) names.push_back(entry.first);
    check_.fail(node, what + ": no interface type '" + name + "'" + suggestion(name, names) +
                          (names.empty() ? "; the model has no interface_types" : "; interface types: " + join(names)));
  }

  void read_train(const YAML::Node& train) {
    check_.check_map_keys(train, kTrainKeys, "each train");
    const std::string name = check_.word(check_.required(train, "name", "train"), "train name");
    const std::string what = "train '" + name + "'";
    if (!trains_.insert(name).second) check_.fail(train["name"], what + ": two trains have this name");
    double front = train["front"] ? check_.number(train["front"], what + ": front") : 0.0;
    double facing = 1.0;
    if (train["facing"]) {
      const std::string f = check_.word(train["facing"], what + ": facing");
      if (f == "-x") facing = -1.0;
      else if (f != "+x") check_.fail(train["facing"], what + ": facing must be +x or -x (where the train's front points)");
    }
    const double speed = train["speed"] ? check_.number(train["speed"], what + ": speed") : 0.0;
    const YAML::Node cars = check_.required(train, "cars", what);
    check_.require_list(cars, what + ": cars");
    if (cars.size() == 0) check_.fail(cars, what + ": cars is empty; list at least one car {type: ...}");
    if (train["coupling"] && train["couplings"])
      check_.fail(train["couplings"], what + ": give either 'coupling' (for every gap) or 'couplings' (one per gap), not both");
    if (train["couplings"]) {
      check_.require_list(train["couplings"], what + ": couplings");
      if (train["couplings"].size() != cars.size() - 1)
        check_.fail(train["couplings"], what + ": couplings must list " + std::to_string(cars.size() - 1) +
                                            " couplings (one per gap between " + std::to_string(cars.size()) + " cars), not " +
                                            std::to_string(train["couplings"].size()));
    } else if (cars.size() > 1 && !train["coupling"]) {
      check_.fail(train, what + ": " + std::to_string(cars.size()) + " cars need 'coupling: {type: <interface type>, gap: 0}'");
    }
    std::set<std::string> car_names;
    CarInstance previous;
    double leading_x = front;
    for (std::size_t k = 0; k < cars.size(); ++k) {
      const YAML::Node car = cars[k];
      const std::string cw = what + ": car " + std::to_string(k + 1);
      check_.check_map_keys(car, kCarKeys, cw);
      const CarType& type = car_type(check_.required(car, "type", cw), cw + ": type");
      const std::string car_name = car["name"] ? check_.word(car["name"], cw + ": name") : "car" + std::to_string(k + 1);
      if (!car_names.insert(car_name).second) check_.fail(car["name"] ? car["name"] : car, cw + ": two cars are named '" + car_name + "'");
      bool reversed = false;
      if (car["reversed"]) {
        try {
          reversed = car["reversed"].as<bool>();
        } catch (const YAML::Exception&) {
          check_.fail(car["reversed"], cw + ": reversed must be true or false");
        }
      }
      if (k > 0) {  // the coupling to the previous car, and this car's leading end behind it
        const YAML::Node coupling = train["couplings"] ? train["couplings"][k - 1] : train["coupling"];
        const std::string kw = what + ": coupling " + std::to_string(k);
        check_.check_map_keys(coupling, kCouplingKeys, kw);
        const double gap = coupling["gap"] ? check_.number(coupling["gap"], kw + ": gap") : 0.0;
        leading_x = previous.trailing.x - facing * gap;
      }
      const CarInstance placed = place_car(type, name + "." + car_name, car, leading_x, facing, reversed, speed);
      if (k > 0) {
        const YAML::Node coupling = train["couplings"] ? train["couplings"][k - 1] : train["coupling"];
        const std::string kw = what + ": coupling " + std::to_string(k);
        const YAML::Node type_node = check_.required(coupling, "type", kw);
        const CarEnd& lower = facing > 0 ? placed.leading : previous.trailing;
        const CarEnd& upper = facing > 0 ? previous.trailing : placed.leading;
        join_ends(interface_type(type_node, kw + ": type"), name + ".coupling" + std::to_string(k), lower, upper,
                  "coupling " + name + ".coupling" + std::to_string(k) + " (line " + std::to_string(yaml_line(coupling)) + ")");
      }
      previous = placed;
    }
  }

  CarInstance place_car(const CarType& type, const std::string& name, const YAML::Node& where, double leading_x, double facing,
                        bool reversed, double speed) {
    Placement p;
    p.mirror = reversed ? -facing : facing;
    const CarType::Interface& lead = reversed ? type.rear : type.front;
    const CarType::Interface& trail = reversed ? type.front : type.rear;
    p.anchor = leading_x - p.mirror * lead.x;
    edit_.note = expansion_.note(" (car type '" + type.name + "', line " + std::to_string(type.line) + "; instance " + name +
                                 ", line " + std::to_string(yaml_line(where)) + ")");
    const int type_line = type.line;
    ExpandedCar summary{name, type.name, reversed, 0.0, 0.0, 0, 0};
    for (const YAML::Node& b : type.node["bodies"]) {
      YAML::Node body = edit_.copy(b, type_line);
      const int line = yaml_line(b);
      edit_.set(body["name"], name + "." + b["name"].Scalar());
      const std::string bw = "car type '" + type.name + "': body '" + b["name"].Scalar() + "'";
      const auto position = check_.pair(check_.required(b, "position", bw), bw + ": position");
      edit_.set(body["position"][0], p.x(position[0]));
      if (b["angle"] && p.mirror < 0) edit_.set(body["angle"], -check_.number(b["angle"], bw + ": angle"));
      if (b["angular_velocity"] && p.mirror < 0)
        edit_.set(body["angular_velocity"], -check_.number(b["angular_velocity"], bw + ": angular_velocity"));
      double vx = 0.0, vy = 0.0;
      if (b["velocity"]) {
        const auto v = check_.pair(b["velocity"], bw + ": velocity");
        vx = p.mirror * v[0];
        vy = v[1];
      }
      vx += facing * speed;
      if (b["velocity"]) edit_.set(body["velocity"][0], vx);
      else if (vx != 0.0 || vy != 0.0) edit_.insert(body, "velocity", edit_.fresh_pair(vx, vy, line), line);
      if (b["car"]) edit_.set(body["car"], name);
      else edit_.insert(body, "car", edit_.scalar(name, line), line);
      bodies_.push_back(body);
      ++summary.bodies;
    }
    if (type.node["elements"])
      for (const YAML::Node& e : type.node["elements"]) {
        elements_.push_back(car_element(type, name, e, p));
        ++summary.elements;
      }
    CarInstance car;
    car.name = name;
    const auto end = [&](const CarType::Interface& i) {
      CarEnd out;
      out.body = name + "." + i.body;
      out.sx = p.mirror * i.sx;
      out.sy = i.sy;
      out.x = p.x(i.x);
      out.y = i.y;
      out.where = where;
      return out;
    };
    car.front = end(type.front);
    car.rear = end(type.rear);
    car.leading = end(lead);
    car.trailing = end(trail);
    summary.leading_x = car.leading.x;
    summary.trailing_x = car.trailing.x;
    expansion_.cars.push_back(summary);
    cars_[name] = car;
    return car;
  }

  /// One element of a car type, placed.
  YAML::Node car_element(const CarType& type, const std::string& car, const YAML::Node& e, const Placement& p) {
    const std::string ew = "car type '" + type.name + "': element";
    check_.require_map(e, ew);
    const std::string element_name = check_.word(check_.required(e, "name", ew), ew + " name");
    YAML::Node element = edit_.copy(e, yaml_line(e));
    edit_.set(element["name"], car + "." + element_name);
    const std::string what = "car type '" + type.name + "': element '" + element_name + "'";
    if (e["points"] && e["points"].IsSequence())
      for (std::size_t k = 0; k < e["points"].size(); ++k) {
        const YAML::Node point = e["points"][k];
        if (!point.IsMap() || !point["body"] || !point["body"].IsScalar()) continue;  // the loader says what is wrong
        YAML::Node copied = element["points"][k];
        const std::string body = point["body"].Scalar();
        const auto at = point["at"] ? check_.pair(point["at"], what + ": point " + std::to_string(k + 1) + ": at")
                                    : std::array<double, 2>{0.0, 0.0};
        if (body == "ground") {  // a point fixed in the world: car coordinates placed
          if (point["at"]) edit_.set(copied["at"][0], p.x(at[0]));
          else edit_.insert(copied, "at", edit_.fresh_pair(p.x(0.0), 0.0, yaml_line(point)), yaml_line(point));
          continue;
        }
        if (std::find(type.body_names.begin(), type.body_names.end(), body) == type.body_names.end())
          check_.fail(point["body"], what + ": point " + std::to_string(k + 1) + ": no body '" + body + "' in the car type" +
                                         suggestion(body, type.body_names) + "; its bodies are: " + join(type.body_names) +
                                         " (and ground)");
        edit_.set(copied["body"], car + "." + body);
        if (point["at"] && p.mirror < 0) edit_.set(copied["at"][0], -at[0]);
      }
    // Parameters that hold directions or global positions follow the placement.
    if (e["type"] && e["type"].IsScalar())
      if (const ElementType* t = ElementRegistry::instance().find(e["type"].Scalar()))
        for (const ParameterSpec& spec : t->parameters) {
          if (spec.name == "facing" && spec.unit == Unit::Choice && e["facing"] && p.mirror < 0)  // 1 | -1: which way a face looks
            edit_.set(element["facing"], -check_.number(e["facing"], what + ": facing"));
          if (spec.shape != Shape::Pair || !e[spec.name]) continue;
          if (spec.unit != Unit::Direction && spec.unit != Unit::Position) continue;
          // Checked before `element[spec.name][0]` is touched: indexing a scalar throws yaml-cpp's BadSubscript,
          // and a function's arguments may be evaluated in either order (clang took the index first).
          const double x = check_.pair(e[spec.name], what + ": " + spec.name)[0];
          if (spec.unit == Unit::Direction && p.mirror < 0) edit_.set(element[spec.name][0], -x);
          if (spec.unit == Unit::Position) edit_.set(element[spec.name][0], p.x(x));
        }
    return element;
  }

  /// The elements of an interface type between two ends (`lower` at the smaller x: end 1).
  void join_ends(const std::pair<YAML::Node, std::string>& named_type, const std::string& prefix, const CarEnd& lower,
                 const CarEnd& upper, const std::string& instance) {
    const YAML::Node& type = named_type.first;
    edit_.note = expansion_.note(" (interface type '" + named_type.second + "', line " +
                                 std::to_string(interface_type_lines_[named_type.second]) + "; " + instance + ")");
    if (!type["elements"]) return;
    check_.require_list(type["elements"], "interface type: elements");
    for (const YAML::Node& e : type["elements"]) {
      check_.require_map(e, "interface type: each element");
      const std::string element_name = check_.word(check_.required(e, "name", "interface type: element"), "interface type: element name");
      const std::string what = "interface type: element '" + element_name + "'";
      YAML::Node element = edit_.copy(e, yaml_line(e));
      edit_.set(element["name"], prefix + "." + element_name);
      const YAML::Node points = check_.required(e, "points", what);
      check_.require_list(points, what + ": points");
      YAML::Node placed = edit_.make(YAML::EmitterStyle::Flow);
      for (std::size_t k = 0; k < points.size(); ++k) {
        const YAML::Node point = points[k];
        const std::string pw = what + ": point " + std::to_string(k + 1);
        check_.check_map_keys(point, kEndPointKeys, pw + " (an interface point is {end: 1 | 2, at: [dx, dy]})");
        const YAML::Node end_node = check_.required(point, "end", pw);
        const std::string end = check_.word(end_node, pw + ": end");
        if (end != "1" && end != "2") check_.fail(end_node, pw + ": end must be 1 (the end at smaller x) or 2");
        const CarEnd& at_end = end == "1" ? lower : upper;
        const auto offset = point["at"] ? check_.pair(point["at"], pw + ": at") : std::array<double, 2>{0.0, 0.0};
        YAML::Node out = edit_.make(YAML::EmitterStyle::Flow);
        edit_.insert(out, "body", edit_.scalar(at_end.body, yaml_line(end_node)), yaml_line(point));
        edit_.insert(out, "at", edit_.fresh_pair(at_end.sx + offset[0], at_end.sy + offset[1], yaml_line(point)), yaml_line(point));
        placed.push_back(edit_.fresh(out, yaml_line(point)));
      }
      element["points"] = edit_.fresh(placed, yaml_line(points));
      elements_.push_back(element);
    }
  }

  void read_connection(const YAML::Node& connection) {
    check_.check_map_keys(connection, kConnectionKeys, "each connection");
    const std::string name = check_.word(check_.required(connection, "name", "connection"), "connection name");
    const std::string what = "connection '" + name + "'";
    const YAML::Node ends = check_.required(connection, "ends", what);
    if (!ends.IsSequence() || ends.size() != 2)
      check_.fail(ends, what + ": ends must be two interfaces [<train>.<car>.front|rear, <train>.<car>.front|rear]");
    std::vector<CarEnd> found;
    for (const YAML::Node& e : ends) {
      const std::string ref = check_.word(e, what + ": end");
      const auto dot = ref.rfind('.');
      const std::string car = dot == std::string::npos ? "" : ref.substr(0, dot), side = dot == std::string::npos ? "" : ref.substr(dot + 1);
      const auto it = cars_.find(car);
      if (it == cars_.end() || (side != "front" && side != "rear")) {
        std::vector<std::string> names;
        for (const auto& c : cars_) names.push_back(c.first);
        check_.fail(e, what + ": '" + ref + "' is not an interface; write <train>.<car>.front or .rear" +
                           suggestion(car, names) + "; cars: " + join(names));
      }
      found.push_back(side == "front" ? it->second.front : it->second.rear);
    }
    const bool swap = found[1].x < found[0].x;
    join_ends(interface_type(check_.required(connection, "type", what), what + ": type"), name, found[swap ? 1 : 0],
              found[swap ? 0 : 1], "connection " + name + " (line " + std::to_string(yaml_line(connection)) + ")");
  }

  YAML::Node& root_;
  const YAML::Node doc_;  // the document as read (const: reading a key never adds it)
  Checker check_;
  TrainExpansion& expansion_;
  Editor edit_;
  std::vector<CarType> car_types_;
  std::map<std::string, YAML::Node> interface_types_;
  std::map<std::string, int> interface_type_lines_;  // the line of each one's name
  std::set<std::string> trains_;
  std::map<std::string, CarInstance> cars_;
  YAML::Node bodies_ = edit_.make(), elements_ = edit_.make();  // the generated ones (the pool's)
};

/// KEY, the operator ("=" or "*=") and the text after it; InputError when there is none.
struct ParsedSetting {
  std::vector<std::string> path;
  bool scale = false;
  std::string value;
};

ParsedSetting parse_setting(const std::string& setting, const std::string& where) {
  ParsedSetting out;
  const auto star = setting.find("*=");
  const auto equals = setting.find('=');
  if (equals == std::string::npos || equals == 0)
    throw InputError(where + "expected KEY=VALUE, e.g. car_types.coach.bodies.body.mass=40000");
  out.scale = star != std::string::npos && star + 1 == equals;
  out.path = split(setting.substr(0, out.scale ? star : equals), '.');
  out.value = setting.substr(equals + 1);
  return out;
}

/// Sets (or scales) `key` of `holder` to the setting's value. The key is marked as the setting's
/// too, unless it was there already and `mark_existing_key` is false: an expanded instance's keys
/// are its car type's own nodes, shared with every other instance (Editor::shared_key), and a
/// setting on one instance must not claim them for the others' messages.
void set_value(YAML::Node holder, const std::string& key, const ParsedSetting& s, const std::string& label,
               const std::string& shown_key, const MarkSetting& mark, bool mark_existing_key = true) {
  const std::string where = label + ": ";
  const YAML::Node& view = holder;  // (const: looking never adds the key)
  const bool mark_key = mark_existing_key || !view[key].IsDefined();
  if (s.scale) {
    double factor = 0.0, value = 0.0;
    try {
      factor = std::stod(s.value);
    } catch (const std::exception&) {
      throw InputError(where + "expected KEY*=FACTOR with a number, e.g. car_types.coach.elements.front_crush.stiffness*=1.2");
    }
    if (!holder[key] || !holder[key].IsScalar()) throw InputError(where + "there is no number at '" + shown_key + "' to scale");
    try {
      value = holder[key].as<double>();
    } catch (const YAML::Exception&) {
      throw InputError(where + "'" + holder[key].Scalar() + "' is not a number");
    }
    if (value == 0.0 && factor != 1.0)
      throw ZeroScaledError(where + "'" + shown_key + "' is 0 in the model, so a factor changes nothing; "
                            "set a value with KEY=VALUE instead (or leave this parameter out)");
    holder[key] = number_text(value * factor);
    if (mark_key)
      for (const auto& entry : holder)
        if (entry.first.IsScalar() && entry.first.Scalar() == key) mark(entry.first, label);
    return;
  }
  YAML::Node value;
  try {
    value = load_yaml_text(s.value, label);
  } catch (const YAML::Exception& e) {
    throw InputError(where + "the value is not valid YAML (" + e.msg + ")");
  }
  mark(value, label);
  holder[key] = value;
  if (mark_key)
    for (const auto& entry : holder)
      if (entry.first.IsScalar() && entry.first.Scalar() == key) mark(entry.first, label);
}

}  // namespace

bool is_train_definition_setting(const std::string& setting) {
  for (const std::string& section : kDefinitionSections)
    if (setting.rfind(section + ".", 0) == 0 || setting.rfind(section + "=", 0) == 0) return true;
  return false;
}

void apply_train_definition_setting(YAML::Node& root, const std::string& setting, const std::string& label,
                                    const MarkSetting& mark) {
  const std::string where = label + ": ";
  const ParsedSetting s = parse_setting(setting, where);
  YAML::Node node = root;
  std::string walked;
  for (std::size_t k = 0; k + 1 < s.path.size(); ++k) {
    const std::string& part = s.path[k];
    YAML::Node next;
    if (node.IsMap()) {
      next = node[part];
    } else if (node.IsSequence()) {
      for (const YAML::Node& item : node)
        if (item.IsMap() && item["name"] && item["name"].IsScalar() && item["name"].Scalar() == part) next = item;
    }
    if (!next || (!next.IsMap() && !next.IsSequence())) {
      std::vector<std::string> known;
      if (node.IsMap())
        for (const auto& entry : node) known.push_back(entry.first.Scalar());
      if (node.IsSequence())
        for (const YAML::Node& item : node)
          if (item.IsMap() && item["name"] && item["name"].IsScalar()) known.push_back(item["name"].Scalar());
      throw InputError(where + "the model has no '" + part + "' in '" + (walked.empty() ? "the model" : walked) + "'" +
                       suggestion(part, known) + (known.empty() ? "" : "; there are: " + join(known)));
    }
    walked += (walked.empty() ? "" : ".") + part;
    node.reset(next);  // (assigning would change the node it held)
  }
  if (!node.IsMap())
    throw InputError(where + "'" + walked + "' is a list; name one of its items (by its name) before the key");
  set_value(node, s.path.back(), s, label, walked.empty() ? s.path.back() : walked + "." + s.path.back(), mark);
}

bool apply_instance_setting(YAML::Node& root, const std::string& setting, const std::string& label, const MarkSetting& mark) {
  const auto equals = setting.find('=');
  if (equals == std::string::npos || !root.IsMap()) return false;
  const std::string key = setting.substr(0, setting.compare(equals - 1, 1, "*") == 0 && equals > 0 ? equals - 1 : equals);
  const auto dot = key.rfind('.');
  if (dot == std::string::npos || key.find('.') == dot) return false;  // a generated name has a '.'
  const std::string name = key.substr(0, dot);
  for (const char* section : {"bodies", "elements"}) {
    const YAML::Node list = root[section];
    if (!list || !list.IsSequence()) continue;
    for (const YAML::Node& item : list)
      if (item.IsMap() && item["name"] && item["name"].IsScalar() && item["name"].Scalar() == name) {
        set_value(item, key.substr(dot + 1), parse_setting(setting, label + ": "), label, key, mark, false);
        return true;
      }
  }
  return false;
}

YAML::Node unshared_copy(const YAML::Node& node) {
  YAML::Node pool(YAML::NodeType::Sequence);  // every copy in one memory (as Editor::make)
  std::size_t used = 0;
  const std::function<YAML::Node(const YAML::Node&)> copy = [&](const YAML::Node& from) {
    YAML::Node out = pool[used++];
    out.SetStyle(from.Style());
    if (from.IsScalar()) {
      out = from.Scalar();
    } else if (from.IsSequence()) {
      for (const YAML::Node& item : from) out.push_back(copy(item));
    } else if (from.IsMap()) {
      for (const auto& entry : from) out.force_insert(copy(entry.first), copy(entry.second));
    }
    if (!from.Tag().empty()) out.SetTag(from.Tag());
    return out;
  };
  return copy(node);
}

void expand_trains(YAML::Node& root, const std::string& file, TrainExpansion& expansion, const SettingOf& setting_of,
                   const MarkSetting& mark) {
  if (!root.IsMap()) return;
  bool any = false;
  for (const std::string& key : kDefinitionSections) any = any || root[key];
  if (!any) return;
  Expander(root, file, expansion, setting_of, mark).run();
}

std::vector<std::pair<std::string, std::vector<std::string>>> train_expansion_sections() {
  return {{"sections", kDefinitionSections}, {"car_type", kCarTypeKeys}, {"interface_type", kInterfaceTypeKeys},
          {"interface", kInterfaceKeys},     {"train", kTrainKeys},       {"car", kCarKeys},
          {"coupling", kCouplingKeys},       {"connection", kConnectionKeys}, {"end_point", kEndPointKeys}};
}

}  // namespace railcrash
