// EN 15227 design collision scenarios (scenario/en15227.hpp says what is built and from which sources).
#include "railcrash/scenarios/en15227.hpp"

#include <yaml-cpp/yaml.h>

#include <cctype>
#include <cstdio>
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "railcrash/core/error.hpp"
#include "railcrash/model/element.hpp"
#include "railcrash/model/model.hpp"
#include "railcrash/model/model_io.hpp"
#include "railcrash/model/train_expansion.hpp"
#include "railcrash/model/yaml_file.hpp"
#include "railcrash/results/crush_zones.hpp"
#include "railcrash/scenarios/consist.hpp"
#include "railcrash/scenarios/train_unit.hpp"

namespace railcrash {
namespace {

constexpr double kPoundForce = 4.4482216152605;  // [N]
constexpr double kPoundMass = 0.45359237;     // [kg]
// The unit systems' own constants (model.hpp): the inch in metres, standard gravity.
const double kInch = metres_per_length_unit(UnitSystem::InLbfS);               // [m]
const double kStandardGravitySI = standard_gravity(UnitSystem::SI);            // [m/s^2]
const double kStandardGravityInch = standard_gravity(UnitSystem::InLbfS);      // [in/s^2]

/// Conversions from the command's units (km/h, mm, kN, t) to the model's.
struct Units {
  bool inch_pound = false;
  bool millimetre = false;  // mm-t-s-N (the loader converts it to SI; the file keeps it)
  double length(double mm) const { return inch_pound ? mm / 25.4 : millimetre ? mm : mm * 1e-3; }
  double speed(double kmh) const { return inch_pound ? kmh / 3.6 / kInch : millimetre ? kmh / 3.6 * 1e3 : kmh / 3.6; }
  double force(double kn) const { return inch_pound ? kn * 1e3 / kPoundForce : kn * 1e3; }
  double acceleration(double g) const {
    return g * (inch_pound ? kStandardGravityInch : millimetre ? kStandardGravitySI * 1e3 : kStandardGravitySI);
  }
  const char* length_name() const { return inch_pound ? "in" : millimetre ? "mm" : "m"; }
  const char* speed_name() const { return inch_pound ? "in/s" : millimetre ? "mm/s" : "m/s"; }
  /// A mass [t] as the model file gives it: in-lbf-s its weight [lbf], mm-t-s-N [t], SI [kg].
  double mass(double tonnes) const { return inch_pound ? tonnes * 1e3 / kPoundMass : millimetre ? tonnes : tonnes * 1e3; }
  const char* mass_name() const { return inch_pound ? " lbf weight" : millimetre ? " t" : " kg"; }
  /// The same mass in the model's mass unit (in-lbf-s: lbf s^2/in).
  double model_mass(double tonnes) const { return inch_pound ? mass(tonnes) / kStandardGravityInch : mass(tonnes); }
  static Units of(const std::string& system) {
    Units u;
    u.inch_pound = system == "in-lbf-s";
    u.millimetre = system == "mm-t-s-N";
    return u;
  }
};

[[noreturn]] void refuse(const std::string& message) { throw InputError("scenario: " + message); }

double required(const std::optional<double>& value, const std::string& option, const std::string& what) {
  if (!value) refuse("missing " + option + ": " + what);
  if (!(*value > 0.0)) refuse(option + " must be positive");
  return *value;
}

std::string number_text(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

bool starts_with(const std::string& text, const std::string& prefix) { return text.rfind(prefix, 0) == 0; }

/// Deep copy with car1_X renamed car2_X and every x coordinate of positions, velocities, body
/// points and directions negated: the mirror image of the striking car about x = 0.
YAML::Node mirrored(const YAML::Node& node) {
  return transformed_node(
      node, [](const std::string&, const std::string& scalar) { return starts_with(scalar, "car1_") ? "car2_" + scalar.substr(5) : scalar; },
      true);
}

struct Template {
  std::string path;
  YAML::Node root;
  Units units;
  std::string anticlimber;   // interface anticlimber's name ("" if none)
  YAML::Node anticlimber_node;
  std::vector<std::string> leading_wheels;  // the striking car's wheel_rail elements on its foremost wheel-carrying body

  [[noreturn]] void fail(const YAML::Node& node, const std::string& what) const { ScenarioModelReader(path).fail(node, what); }
  YAML::Node body(const std::string& name, const std::string& option = "") const {
    for (const YAML::Node& b : root["bodies"])
      if (b["name"] && b["name"].as<std::string>() == name) return b;
    fail(root["bodies"], "no body named '" + name + "'" + (option.empty() ? "" : " (from " + option + ", which names the template's car1_* bodies without the car1_ prefix)"));
  }
};

Template read_template(const std::string& path) {
  Template t;
  t.path = path;
  try {
    t.root = load_yaml_file(path, "train model");
  } catch (const YAML::Exception& e) {
    throw InputError(path + ": cannot read the train model: " + e.what());
  }
  if (!t.root.IsMap() || !t.root["bodies"] || !t.root["bodies"].IsSequence() || !t.root["elements"] || !t.root["elements"].IsSequence())
    t.fail(t.root, "needs 'bodies' and 'elements' lists");
  const std::string units = t.root["units"] ? t.root["units"].as<std::string>() : "";
  if (units != "SI" && units != "in-lbf-s") t.fail(t.root["units"], "units must be SI or in-lbf-s");
  t.units.inch_pound = units == "in-lbf-s";
  bool coupler = false;
  std::string striking_car;  // the car the car1_* bodies declare
  for (const YAML::Node& b : t.root["bodies"])
    if (striking_car.empty() && starts_with(b["name"].as<std::string>(), "car1_") && b["car"]) striking_car = b["car"].as<std::string>();
  if (striking_car.empty())
    t.fail(t.root["bodies"], "no striking car: the scenario builds its trains from the car declared (car: NAME) by the bodies named "
                             "car1_* (the car at x < 0 whose front faces x = 0), as in models/report/final_two_car.yaml");
  // The interface anticlimber and the leading wheels from the output roles and car declarations.
  const Model model = load_model(path).model;
  const auto car_of = [&](int body) { return body == kGround ? std::string() : model.bodies()[static_cast<std::size_t>(body)].car; };
  double foremost = -1e300;  // [length] x of the striking car's foremost wheel-carrying body
  for (const auto& e : model.elements()) {
    if (e->name() == "coupler_faces" && e->type() == "coupler_end") coupler = true;
    const std::string car_1 = car_of(e->point(0).body), car_2 = e->points().size() == 2 ? car_of(e->point(1).body) : "";
    const bool between_cars = !car_1.empty() && !car_2.empty() && car_1 != car_2;
    if (between_cars && !e->output_with_role(OutputRole::VerticalInterlockForce).empty()) {
      if (car_1 != striking_car) t.fail(t.root["elements"], "the interface element '" + e->name() + "' (vertical interlock) must have its first point on the striking car " + striking_car);
      t.anticlimber = e->name();
      for (const YAML::Node& node : t.root["elements"])
        if (node["name"].as<std::string>() == e->name()) t.anticlimber_node = node;
    }
    if (e->type() == "wheel_rail" && car_1 == striking_car) {
      const double x = model.bodies()[static_cast<std::size_t>(e->point(0).body)].x;
      if (x > foremost + 1e-9) {
        foremost = x;
        t.leading_wheels.clear();
      }
      if (std::abs(x - foremost) <= 1e-9) t.leading_wheels.push_back(e->name());
    }
  }
  if (!coupler)
    t.fail(t.root["elements"], "no coupler: the trains meet at an interface element 'coupler_faces' of type coupler_end "
                               "(car1_coupler to car2_coupler), which the consist generator needs");
  if (t.anticlimber.empty())
    t.fail(t.root["elements"], "no front end: the override criterion needs the interface anticlimber (an element with a vertical "
                               "interlock output between the two cars' front ends, e.g. an anticlimber)");
  if (t.leading_wheels.empty())
    t.fail(t.root["elements"], "no wheel_rail elements on the striking car: the wheel lift-off criterion needs the leading bogie's wheels");
  return t;
}

/// The template with its standing car replaced by the mirror image of the striking car.
YAML::Node identical_pair(const Template& t) {
  YAML::Node root = YAML::Clone(t.root);
  YAML::Node bodies(YAML::NodeType::Sequence), elements(YAML::NodeType::Sequence);
  for (const YAML::Node& b : t.root["bodies"])
    if (starts_with(b["name"].as<std::string>(), "car1_")) bodies.push_back(YAML::Clone(b));
  for (const YAML::Node& b : t.root["bodies"])
    if (starts_with(b["name"].as<std::string>(), "car1_")) bodies.push_back(mirrored(b));
  for (const YAML::Node& e : t.root["elements"]) {
    const std::string name = e["name"].as<std::string>();
    if (starts_with(name, "car2_")) continue;
    if (starts_with(name, "car1_")) {
      elements.push_back(YAML::Clone(e));
      elements.push_back(mirrored(e));
      continue;
    }
    // An interface element: its second point becomes the mirror image of its first.
    YAML::Node copy = YAML::Clone(e);
    if (!copy["points"] || copy["points"].size() != 2) t.fail(e, "interface element '" + name + "' needs two points");
    copy["points"][1] = mirrored(e["points"][0]);
    for (const char* key : {"horizontal_stiffness", "free_length", "coupler_height"})
      if (copy["type"].as<std::string>() == "coupler_end" && copy[key]) copy[key] = flow_pair(e[key][0].as<double>(), e[key][0].as<double>());
    if (is_anticlimber_type(copy["type"].as<std::string>())) copy["initial_misalignment"] = 0.0;
    elements.push_back(copy);
  }
  root["bodies"] = bodies;
  root["elements"] = elements;
  return root;
}

/// The points list [{body: a, at: [..]}, {body: b, at: [..]}] of an element.
YAML::Node two_points(const std::string& body_1, const YAML::Node& at_1, const std::string& body_2, const YAML::Node& at_2) {
  YAML::Node points(YAML::NodeType::Sequence);
  for (const auto& [body, at] : {std::make_pair(body_1, at_1), std::make_pair(body_2, at_2)}) {
    YAML::Node point(YAML::NodeType::Map);
    point["body"] = body;
    point["at"] = at;
    point.SetStyle(YAML::EmitterStyle::Flow);
    points.push_back(point);
  }
  return points;
}

/// True for the standing train's names, t<k>_* (the consist generator's).
bool is_standing(const std::string& name) { return name.size() > 1 && name[0] == 't' && std::isdigit(static_cast<unsigned char>(name[1])); }

/// True when an element's points list names a body of the standing train.
bool touches_standing_train(const YAML::Node& points) {
  for (const YAML::Node& point : points)
    if (point["body"] && is_standing(point["body"].as<std::string>())) return true;
  return false;
}

/// The trains of a scenario and what its criteria are measured on.
struct Trains {
  YAML::Node model;                             // the whole model: the trains' bodies and elements
  std::vector<std::string> cars;                // survival space: the crush of each car
  std::vector<std::string> passenger_bodies;
  std::vector<std::array<std::string, 3>> gauges;  // survival gauges: name, front body, rear body
  std::vector<std::string> excluded;            // crush elements that are not the train's (the struck body's)
  std::vector<std::pair<std::string, std::optional<double>>> zones;  // declared crush zones, stroke [mm] if given
  std::vector<std::string> rail_supports;       // slider_joints holding the leading bogies (no wheel_rail)
  std::string striking_label = "s*", standing_label = "t*";  // the trains' names in the header
  std::vector<std::string> wheels;              // the leading bogies' wheel_rail elements
  std::string interface_element;                // the anticlimber between two template-built trains
  std::vector<std::string> interface_bodies;    // otherwise the two bodies meeting at the interface
  std::string front_body;                       // the striking train's front (the struck body meets it)
  double front_x = 0.0, front_y = 0.0;          // [length] its centre of gravity
  double face_x = 0.0;                          // [length] the front face
  int cars_per_train = 1;
  std::ostringstream header;                    // the model file's comment lines
};

/// A --crush-zones entry NAME or NAME:STROKE [mm].
std::pair<std::string, std::optional<double>> crush_zone(const std::string& entry) {
  const auto colon = entry.find(':');
  if (colon == std::string::npos) return {entry, std::nullopt};
  double stroke = 0.0;
  try {
    std::size_t used = 0;
    stroke = std::stod(entry.substr(colon + 1), &used);
    if (used != entry.size() - colon - 1) throw std::invalid_argument("trailing");
  } catch (const std::exception&) {
    refuse("--crush-zones " + entry + ": the stroke after ':' must be a number [mm] (NAME:STROKE)");
  }
  if (!(stroke > 0.0) || !std::isfinite(stroke)) refuse("--crush-zones " + entry + ": the stroke must be positive [mm]");
  return {entry.substr(0, colon), stroke};
}

std::vector<std::string> crush_zone_names(const std::vector<std::string>& entries) {
  std::vector<std::string> names;
  for (const std::string& entry : entries) names.push_back(crush_zone(entry).first);
  return names;
}

/// The declared crush zones of the cars named by `prefixes` + each --crush-zones entry.
void add_zones(Trains& trains, const std::vector<std::string>& prefixes, const std::vector<std::string>& entries) {
  for (const std::string& prefix : prefixes)
    for (const std::string& entry : entries) {
      const auto zone = crush_zone(entry);
      trains.zones.push_back({prefix + zone.first, zone.second});
    }
}

/// Refuses a --crush-zones name that is no element of the train model.
void check_crush_zones(const YAML::Node& root, const std::string& path, const std::vector<std::string>& entries, const std::string& prefix) {
  for (const std::string& name : crush_zone_names(entries)) {
    bool found = false;
    for (const YAML::Node& e : root["elements"]) found = found || (e["name"] && e["name"].as<std::string>() == prefix + name);
    if (!found)
      throw InputError(path + ": scenario train model: no element named '" + prefix + name + "' (from --crush-zones, which names the " +
                       "crush elements of a car whose crush up to their stroke is allowed" + (prefix.empty() ? "" : ", without the car1_ prefix") + ")");
  }
}

/// Names of the generated cars' bodies: `prefix` + template name, for every prefix.
void add_names(std::vector<std::string>& to, const std::vector<std::string>& prefixes, const std::vector<std::string>& names) {
  for (const std::string& prefix : prefixes)
    for (const std::string& name : names) to.push_back(prefix + name);
}

/// Trains from a two-car template (car1_* striking, car2_* standing) through the consist generator.
void template_trains(const ScenarioRequest& q, const Template& t, double closing_speed, double offset, Trains& trains) {
  for (const std::string& b : q.passenger_bodies) t.body("car1_" + b, "--passenger-bodies");
  for (const std::string& b : q.survival_gauge) t.body("car1_" + b, "--survival-gauge");
  check_crush_zones(t.root, q.train_path, q.crush_zones, "car1_");
  trains.model = YAML::Load(make_consist_model(identical_pair(t), q.train_path, q.cars));
  trains.cars_per_train = q.cars;
  const bool standing_train = q.number == 1;
  std::vector<std::string> car_prefixes;
  for (const std::string train : {"s", "t"})
    for (int k = 1; k <= q.cars && (train == "s" || standing_train); ++k) car_prefixes.push_back(train + std::to_string(k) + "_");
  for (const std::string& prefix : car_prefixes) {
    const std::string car = prefix.substr(0, prefix.size() - 1);
    trains.cars.push_back(car);
    add_names(trains.passenger_bodies, {prefix}, q.passenger_bodies);
    if (!q.survival_gauge.empty()) trains.gauges.push_back({car, prefix + q.survival_gauge[0], prefix + q.survival_gauge[1]});
    add_zones(trains, {prefix}, q.crush_zones);
  }
  std::vector<std::string> wheels;
  for (const std::string& w : t.leading_wheels) wheels.push_back(w.substr(5));
  add_names(trains.wheels, standing_train ? std::vector<std::string>{"s1_", "t1_"} : std::vector<std::string>{"s1_"}, wheels);
  const YAML::Node face = t.anticlimber_node["points"][0];  // the anticlimber's face on the striking train
  const YAML::Node front = t.body(face["body"].as<std::string>());
  trains.front_body = "s1_" + face["body"].as<std::string>().substr(5);
  trains.front_x = front["position"][0].as<double>();
  trains.front_y = front["position"][1].as<double>();
  trains.face_x = trains.front_x + face["at"][0].as<double>();
  YAML::Node bodies = trains.model["bodies"];
  if (standing_train) {
    trains.interface_element = t.anticlimber;
    for (YAML::Node b : bodies) {
      const bool striking = !is_standing(b["name"].as<std::string>());
      b["velocity"] = flow_pair(striking ? closing_speed / 2 : -closing_speed / 2, 0.0);
      if (!striking) b["position"] = flow_pair(b["position"][0].as<double>(), b["position"][1].as<double>() + offset);
    }
    for (YAML::Node e : trains.model["elements"])
      if (e["type"].as<std::string>() == "wheel_rail" && is_standing(e["name"].as<std::string>()))
        e["rail_height"] = (e["rail_height"] ? e["rail_height"].as<double>() : 0.0) + offset;
    return;
  }
  // Scenarios 2 and 3: the striking train alone, at the closing speed.
  YAML::Node kept_bodies(YAML::NodeType::Sequence), kept_elements(YAML::NodeType::Sequence);
  for (YAML::Node b : bodies)
    if (!is_standing(b["name"].as<std::string>())) {
      b["velocity"] = flow_pair(closing_speed, 0.0);
      kept_bodies.push_back(b);
    }
  for (const YAML::Node& e : trains.model["elements"])
    if (!touches_standing_train(e["points"])) kept_elements.push_back(e);
  trains.model["bodies"] = kept_bodies;
  trains.model["elements"] = kept_elements;
}

/// Trains from a model whose bodies declare their cars (scenarios/train_unit.hpp): the striking
/// train s_* is the model's unit, the standing one t_* its mirror image; their front faces meet
/// at an uncoupled coupler_end (front_faces) with the given face stiffness and height.
void unit_trains(const ScenarioRequest& q, const TrainUnit& unit, const Units& u, double closing_speed, double offset, Trains& trains) {
  if (q.cars != 1)
    refuse("--cars " + std::to_string(q.cars) + ": a train built from the cars that " + q.train_path +
           " declares is that model's unit as it is coupled there; leave --cars out");
  for (const std::string& b : q.passenger_bodies) unit.body(b, "--passenger-bodies");
  for (const std::string& b : q.survival_gauge) unit.body(b, "--survival-gauge");
  check_crush_zones(unit.root, q.train_path, q.crush_zones, "");
  const bool standing_train = q.number == 1;
  if (standing_train) {
    required(q.face_stiffness, "--face-stiffness", "the stiffness of each front face where the two trains meet [kN/mm] (the model "
                                                   "meets a barrier, not a second train)");
    required(q.face_height, "--face-height", "the height of each front face: they push only while they overlap vertically [mm]");
    if (offset > 0.0)
      required(q.face_friction, "--face-friction", "the friction coefficient between the front faces: with a vertical offset, "
                                                   "vertical friction is what lets the offset act (frictionless faces slide past "
                                                   "each other and override cannot develop)");
  }
  trains.model = YAML::Clone(unit.root);
  YAML::Node bodies(YAML::NodeType::Sequence), elements(YAML::NodeType::Sequence);
  append_unit(unit, {"s_", false, 0.0, standing_train ? closing_speed / 2 : closing_speed}, bodies, elements);
  if (standing_train) append_unit(unit, {"t_", true, offset, closing_speed / 2}, bodies, elements);
  const std::vector<std::string> prefixes = standing_train ? std::vector<std::string>{"s_", "t_"} : std::vector<std::string>{"s_"};
  std::vector<std::string> cars;
  for (const YAML::Node& b : unit.root["bodies"])
    if (b["car"] && std::find(cars.begin(), cars.end(), b["car"].as<std::string>()) == cars.end()) cars.push_back(b["car"].as<std::string>());
  add_names(trains.cars, prefixes, cars);
  trains.cars_per_train = static_cast<int>(cars.size());
  add_names(trains.passenger_bodies, prefixes, q.passenger_bodies);
  add_zones(trains, prefixes, q.crush_zones);
  for (const std::string& prefix : prefixes)
    if (!q.survival_gauge.empty()) trains.gauges.push_back({prefix.substr(0, 1), prefix + q.survival_gauge[0], prefix + q.survival_gauge[1]});
  add_names(trains.wheels, prefixes, unit.leading_wheels);
  trains.front_body = "s_" + unit.front_body;
  trains.front_x = unit.front_body_x - unit.face_x;
  trains.front_y = unit.front_body_y;
  trains.face_x = 0.0;
  trains.header << "# Train unit: every body of " << q.train_path << " (cars";
  for (const std::string& car : cars) trains.header << " " << car;
  trains.header << "), its front face at x = 0: the foremost point on " << unit.front_body << ", the front body of its front crush "
                << "element " << unit.front_crush << " (scenarios/train_unit.hpp).\n# Left out (the test's fixed surfaces):";
  for (const std::string& name : unit.fixed_surface_contacts) trains.header << " " << name;
  if (unit.fixed_surface_contacts.empty()) trains.header << " none";
  trains.header << ".\n";
  if (standing_train) {
    // The faces' points: on each front body at its centre of gravity's x and the face's height,
    // the distance to the face behind the face.
    const double behind = unit.face_x - unit.front_body_x;  // [length]
    if (!(behind > 0.0))
      unit.fail(unit.body(unit.front_body, "the front crush element"),
                "the front face of '" + unit.front_body + "' is not ahead of its centre of gravity; the front_faces contact needs it ahead");
    YAML::Node faces(YAML::NodeType::Map);
    faces["name"] = "front_faces";
    faces["type"] = "coupler_end";
    const double stiffness = u.force(*q.face_stiffness) / u.length(1.0), height = u.length(*q.face_height);
    faces["horizontal_stiffness"] = flow_pair(stiffness, stiffness);
    faces["free_length"] = flow_pair(behind, behind);
    faces["coupler_height"] = flow_pair(height, height);
    faces["coupled"] = false;
    if (q.face_friction) faces["friction"] = *q.face_friction;
    faces["points"] = two_points("s_" + unit.front_body, flow_pair(0.0, unit.face_y - unit.front_body_y), "t_" + unit.front_body,
                                 flow_pair(0.0, unit.face_y - unit.front_body_y));
    elements.push_back(faces);
    trains.interface_bodies = {"s_" + unit.front_body, "t_" + unit.front_body};
    trains.header << "# The front faces meet at front_faces (coupler_end, uncoupled): " << *q.face_stiffness << " kN/mm per face (--face-stiffness), "
                  << *q.face_height << " mm high (--face-height)";
    if (q.face_friction) trains.header << ", friction " << *q.face_friction << " (--face-friction)";
    trains.header << ", required inputs.\n";
  }
  trains.model["bodies"] = bodies;
  trains.model["elements"] = elements;
}

/// What strikes the train's front in scenarios 2 and 3: a rigid body on a frictionless slider
/// and a crush_spring between it and the train's front face.
struct StruckBody {
  std::string name, spring_name;
  double mass = 0.0;                                  // [t]
  const std::vector<std::pair<double, double>>* curve;  // [mm, kN] of one unit
  double unloading_stiffness = 0.0;                   // [kN/mm] of one unit
  double height = 0.0;                                // [mm] of the force line above the rail
  int units_in_parallel = 1;                          // two side buffers
};

void add_struck_body(const StruckBody& struck, const Units& u, Trains& trains) {
  const double height = u.length(struck.height);  // [length]
  // [length] the force acts between the train's face and a point 100 m ahead on the struck
  // body: the faces slide on each other, so the force stays within 1/100 rad of horizontal for
  // each metre of vertical relative displacement.
  const double anchor = u.length(100000.0);
  YAML::Node body(YAML::NodeType::Map);
  body["name"] = struck.name;
  body[u.inch_pound ? "weight" : "mass"] = u.mass(struck.mass);
  // Its rotation is locked by the slider, so the inertia only has to be positive (Euler's
  // penalty joints need one): that of the mass at 1 m.
  const double mass_model = u.model_mass(struck.mass);
  const double radius = u.length(1000.0);  // [length] its c.g. 1 m ahead of the train's face
  body["inertia"] = mass_model * radius * radius;
  body["position"] = flow_pair(trains.face_x + radius, height);
  body.SetStyle(YAML::EmitterStyle::Flow);
  trains.model["bodies"].push_back(body);
  YAML::Node slider(YAML::NodeType::Map);
  slider["name"] = struck.name + "_on_track";
  slider["type"] = "slider_joint";
  slider["axis"] = flow_pair(1, 0);
  slider["points"] = two_points("ground", flow_pair(trains.face_x + radius, height), struck.name, flow_pair(0, 0));
  trains.model["elements"].push_back(slider);
  YAML::Node spring(YAML::NodeType::Map);
  spring["name"] = struck.spring_name;
  spring["type"] = "crush_spring";
  YAML::Node curve(YAML::NodeType::Sequence);
  for (const auto& [stroke, force] : *struck.curve) curve.push_back(flow_pair(u.length(stroke), struck.units_in_parallel * u.force(force)));
  spring["curve"] = curve;
  spring["unloading_stiffness"] = struck.units_in_parallel * u.force(struck.unloading_stiffness) / u.length(1.0);
  spring["free_length"] = anchor;
  spring["points"] = two_points(trains.front_body, flow_pair(trains.face_x - trains.front_x, height - trains.front_y), struck.name,
                                flow_pair(anchor - radius, 0));
  trains.model["elements"].push_back(spring);
  trains.excluded.push_back(struck.spring_name);  // its crush is the struck body's, not the train's
}

/// Checks a force-stroke curve and its unloading stiffness [kN/mm]: the crush_spring unloads at
/// it from wherever it is on the curve and stores P^2 / (2 unloading stiffness), so below the
/// curve's steepest slope it would give back more energy than it took.
void check_crush_curve(const std::vector<std::pair<double, double>>& curve, const std::optional<double>& unloading,
                       const std::string& curve_option, const std::string& unloading_option, const std::string& what) {
  if (curve.size() < 2) refuse("missing " + curve_option + ": " + what + " 'mm:kN,mm:kN,...' (at least two points)");
  required(unloading, unloading_option, what + "'s unloading stiffness [kN/mm]");
  double steepest = 0.0;  // [kN/mm]
  for (std::size_t k = 1; k < curve.size(); ++k) {
    const double stroke = curve[k].first - curve[k - 1].first;
    if (!(stroke > 0.0)) refuse(curve_option + ": the strokes must increase (point " + std::to_string(k + 1) + ")");
    steepest = std::max(steepest, (curve[k].second - curve[k - 1].second) / stroke);
  }
  if (*unloading < steepest * (1.0 - 1e-9))
    refuse(unloading_option + " " + number_text(*unloading) + " kN/mm is below the curve's steepest slope " + number_text(steepest) +
           " kN/mm: unloading would give back more energy than it took; give at least that");
}

YAML::Node flow_list(const std::vector<std::string>& names) {
  YAML::Node list(YAML::NodeType::Sequence);
  for (const std::string& name : names) list.push_back(name);
  list.SetStyle(YAML::EmitterStyle::Flow);
  return list;
}

/// The model's `scenario:` section (results/scenario_criteria.hpp).
YAML::Node criteria_section(const ScenarioRequest& q, const Trains& trains, const Units& u, double closing_speed) {
  const std::string input = "required input (not confirmed from a public source)";
  YAML::Node s(YAML::NodeType::Map);
  s["standard"] = "EN 15227";
  s["number"] = q.number;
  s["category"] = q.category;
  s["closing_speed"] = closing_speed;
  YAML::Node deceleration(YAML::NodeType::Map);
  deceleration["limit"] = u.acceleration(*q.deceleration_limit);
  deceleration["cfc"] = 60;
  deceleration["source"] = "--deceleration-limit " + number_text(*q.deceleration_limit) + " g: " + input;
  deceleration["bodies"] = flow_list(trains.passenger_bodies);
  s["mean_deceleration"] = deceleration;
  YAML::Node survival(YAML::NodeType::Map);
  survival["limit"] = u.length(*q.survival_limit);
  survival["source"] = "--survival-space-limit " + number_text(*q.survival_limit) + " mm: " + input;
  survival["cars"] = flow_list(trains.cars);
  if (!trains.excluded.empty()) survival["excluded"] = flow_list(trains.excluded);
  if (!trains.zones.empty()) {
    YAML::Node zones(YAML::NodeType::Sequence);
    for (const auto& [element, stroke] : trains.zones) {
      YAML::Node zone(YAML::NodeType::Map);
      zone["element"] = element;
      zone["stroke"] = *stroke;  // [length] resolved by resolve_zone_strokes
      zone.SetStyle(YAML::EmitterStyle::Flow);
      zones.push_back(zone);
    }
    survival["zones"] = zones;
  }
  if (!trains.gauges.empty()) {
    YAML::Node gauges(YAML::NodeType::Sequence);
    for (const auto& [name, front, rear] : trains.gauges) {
      YAML::Node gauge(YAML::NodeType::Map);
      gauge["name"] = name;
      gauge["front"] = front;
      gauge["rear"] = rear;
      gauge.SetStyle(YAML::EmitterStyle::Flow);
      gauges.push_back(gauge);
    }
    survival["gauges"] = gauges;
  }
  s["survival_space"] = survival;
  YAML::Node override_node(YAML::NodeType::Map);
  if (!trains.interface_element.empty()) override_node["interface"] = trains.interface_element;
  if (!trains.interface_bodies.empty()) override_node["bodies"] = flow_list(trains.interface_bodies);
  if (!trains.rail_supports.empty()) override_node["rail_supports"] = flow_list(trains.rail_supports);
  if (q.number != 3) {
    override_node["limit"] = u.length(*q.override_limit);
    override_node["source"] = "--override-limit " + number_text(*q.override_limit) + " mm: " + input;
  }
  if (!trains.wheels.empty()) {
    override_node["wheel_lift_limit"] = u.length(*q.wheel_lift_limit);
    override_node["wheel_lift_source"] = "--wheel-lift-limit " + number_text(*q.wheel_lift_limit) + " mm: " + input;
    override_node["wheels"] = flow_list(trains.wheels);
  }
  s["override"] = override_node;
  return s;
}

/// Each declared crush zone's stroke in the model's length unit: the given one [mm], or else the
/// end of its declared loading curve (results/crush_zones.hpp: a crush_spring's last curve point,
/// a draft gear's travel, an anticlimber's rupture deflection), the crush its curve declares.
void resolve_zone_strokes(const YAML::Node& model_node, const std::string& path, const Units& u, Trains& trains) {
  for (auto& zone : trains.zones)
    if (zone.second) zone.second = u.length(*zone.second);
  if (trains.zones.empty()) return;
  YAML::Node copy = YAML::Clone(model_node);
  copy["name"] = "scenario";
  YAML::Emitter emitter;
  emitter << copy;
  const Model model = load_model_text(std::string(emitter.c_str()) + "\n", path).model;
  const double to_file = u.millimetre ? 1e3 : 1.0;  // the loaded model is in SI for mm-t-s-N files
  for (auto& [name, stroke] : trains.zones) {
    // (the name through an init-capture: clang refuses to capture a structured binding)
    const auto element = std::find_if(model.elements().begin(), model.elements().end(),
                                      [&zone_name = name](const auto& e) { return e->name() == zone_name; });
    if (element == model.elements().end() || (*element)->output_with_role(OutputRole::Crush).empty())
      refuse("--crush-zones: '" + name + "' has no crush output (OutputRole::Crush): it is not part of a car's survival-space "
             "measure, so declaring it a crush zone would change nothing; leave it out");
    if (stroke) continue;
    const std::optional<DeclaredCurve> curve = declared_curve(**element);
    if (!curve || curve->open_ended || curve->deformation.empty() || !(curve->deformation.back() > 0.0))
      refuse("--crush-zones: '" + name + "' declares no loading curve with an end (a crush_spring's curve, a draft gear's travel, an "
             "anticlimber's rupture deflection); give its stroke, NAME:STROKE [mm]");
    char text[32];  // 12 digits: the file's value back, without the unit conversion's round-off
    std::snprintf(text, sizeof text, "%.12g", curve->deformation.back() * to_file);
    stroke = std::stod(text);
  }
}

/// True for a model with car types and trains (README "Car types and trains").
bool is_car_type_model(const YAML::Node& root) { return root.IsMap() && root["trains"] && root["car_types"]; }

[[noreturn]] void fail_at(const std::string& path, const YAML::Node& node, const std::string& what) {
  ScenarioModelReader(path).fail(node, what);
}

/// The names listed under `key` of a map (its keys), for messages.
std::string keys_of(const YAML::Node& map) {
  std::string list;
  if (map && map.IsMap())
    for (const auto& item : map) list += (list.empty() ? "" : ", ") + item.first.Scalar();
  return list.empty() ? "none" : list;
}

/// Trains from a model with car types and trains: the striking train is the model's train
/// (--unit, default its first), composed as the model composes it; scenario 1's standing train
/// is the same train facing -x, joined to it at the leading cars' leading interfaces by the
/// interface type of the model's connection there (or --interface). The document is expanded
/// here (train_expansion.hpp) so that the standing train and its rails can be raised by the
/// offset; the model's own bodies and elements (the test's wall or wagon), its other trains and
/// connections are left out.
void car_type_trains(const ScenarioRequest& q, const YAML::Node& root, const Units& u, double closing_speed, double offset,
                     Trains& trains) {
  const std::string& path = q.train_path;
  if (q.cars != 1)
    refuse("--cars " + std::to_string(q.cars) + ": a train of " + path + " is composed in its `trains:` section; leave --cars out "
           "(`railcrash consist --cars N` repeats its cars)");
  if (!root["trains"].IsSequence() || root["trains"].size() == 0) fail_at(path, root["trains"], "trains must be a non-empty list");
  std::size_t chosen = root["trains"].size();
  std::string names;
  for (std::size_t k = 0; k < root["trains"].size(); ++k) {
    const std::string name = root["trains"][k]["name"] ? root["trains"][k]["name"].Scalar() : "";
    names += (names.empty() ? "" : ", ") + name;
    if (chosen == root["trains"].size() && (q.unit.empty() || name == q.unit)) chosen = k;
  }
  if (chosen == root["trains"].size()) fail_at(path, root["trains"], "no train named '" + q.unit + "' (from --unit); its trains: " + names);
  const YAML::Node train = root["trains"][chosen];
  const std::string train_name = train["name"] ? train["name"].Scalar() : "";
  const YAML::Node first = train["cars"] && train["cars"].IsSequence() && train["cars"].size() > 0 ? train["cars"][0] : YAML::Node();
  if (!first.IsMap() || !first["type"]) fail_at(path, train, "train '" + train_name + "' has no cars");
  const std::string first_car = first["name"] ? first["name"].Scalar() : "car1";
  const bool reversed = first["reversed"] && first["reversed"].as<bool>();
  const std::string leading = reversed ? "rear" : "front";  // the leading car's leading interface
  const YAML::Node car_type = root["car_types"][first["type"].Scalar()];
  if (!car_type || !car_type["interfaces"] || !car_type["interfaces"][leading] || !car_type["interfaces"][leading]["body"])
    fail_at(path, first, "car type '" + first["type"].Scalar() + "' has no " + leading + " interface {body: ..., at: [..]}");
  const std::string front_body_local = car_type["interfaces"][leading]["body"].Scalar();

  const bool standing_train = q.number == 1;
  std::string interface = q.interface;
  if (standing_train && interface.empty() && root["connections"])
    for (const YAML::Node& connection : root["connections"])
      for (const YAML::Node& end : connection["ends"])
        if (end.Scalar() == train_name + "." + first_car + "." + leading && connection["type"]) interface = connection["type"].Scalar();
  if (standing_train && interface.empty())
    fail_at(path, root["interface_types"] ? root["interface_types"] : root,
            "scenario 1 joins the two trains' leading ends by an interface type, and no connection of the model uses " + train_name + "." +
                first_car + "." + leading + ": give --interface TYPE (its interface types: " + keys_of(root["interface_types"]) +
                "), one whose element has a vertical interlock (an anticlimber), so that the vertical offset can act");
  if (!interface.empty() && !(root["interface_types"] && root["interface_types"][interface]))
    fail_at(path, root["interface_types"] ? root["interface_types"] : root,
            "no interface type '" + interface + "' (from --interface); its interface types: " + keys_of(root["interface_types"]));

  const std::string striking = "striking", standing = "standing";
  YAML::Node doc(YAML::NodeType::Map);
  for (const auto& item : root) {
    const std::string key = item.first.Scalar();
    if (key == "trains" || key == "connections" || key == "bodies" || key == "elements" || key == "scenario" || key == "responses" ||
        key == "outputs")
      continue;
    doc[key] = YAML::Clone(item.second);
  }
  YAML::Node trains_node(YAML::NodeType::Sequence);
  const auto placed = [&](const std::string& name, const char* facing, double speed) {
    YAML::Node copy = YAML::Clone(train);
    copy["name"] = name;
    copy["front"] = 0.0;
    copy["facing"] = facing;
    copy["speed"] = speed;
    trains_node.push_back(copy);
  };
  placed(striking, "+x", standing_train ? closing_speed / 2 : closing_speed);
  if (standing_train) placed(standing, "-x", closing_speed / 2);
  doc["trains"] = trains_node;
  if (standing_train) {
    YAML::Node connection(YAML::NodeType::Map);
    connection["name"] = "impact";
    connection["type"] = interface;
    YAML::Node ends(YAML::NodeType::Sequence);
    ends.push_back(striking + "." + first_car + "." + leading);
    ends.push_back(standing + "." + first_car + "." + leading);
    ends.SetStyle(YAML::EmitterStyle::Flow);
    connection["ends"] = ends;
    YAML::Node connections(YAML::NodeType::Sequence);
    connections.push_back(connection);
    doc["connections"] = connections;
  }
  TrainExpansion expansion;
  expand_trains(doc, path, expansion, [](const YAML::Node&) -> const std::string* { return nullptr; },
                [](const YAML::Node&, const std::string&) {});
  doc.reset(unshared_copy(doc));  // (the expansion shares keys between instances: the text is written from doc)
  // The standing train and its rails (its points on ground) raised by the offset.
  const auto of_standing = [&](const YAML::Node& node) { return node["name"] && starts_with(node["name"].Scalar(), standing + "."); };
  for (YAML::Node b : doc["bodies"])
    if (of_standing(b)) b["position"] = flow_pair(b["position"][0].as<double>(), b["position"][1].as<double>() + offset);
  for (YAML::Node e : doc["elements"]) {
    if (!of_standing(e)) continue;
    for (YAML::Node point : e["points"])
      if (point["body"] && point["body"].Scalar() == "ground" && point["at"])
        point["at"] = flow_pair(point["at"][0].as<double>(), point["at"][1].as<double>() + offset);
    if (e["type"].Scalar() == "wheel_rail") e["rail_height"] = (e["rail_height"] ? e["rail_height"].as<double>() : 0.0) + offset;
  }
  // The two fronts start touching (both at x = 0), so an anticlimber cannot tell from the
  // geometry which way its faces look: end 1 (the striking train's, at the smaller x) faces +x.
  for (YAML::Node e : doc["elements"])
    if (e["name"] && starts_with(e["name"].Scalar(), "impact.") && is_anticlimber_type(e["type"].Scalar()) && !e["facing"]) e["facing"] = 1;
  doc["name"] = "scenario trains";  // replaced below
  YAML::Emitter emitter;
  emitter << doc;
  const Model model = load_model_text(std::string(emitter.c_str()) + "\n", path).model;

  const std::vector<std::string> train_names = standing_train ? std::vector<std::string>{striking, standing} : std::vector<std::string>{striking};
  for (const ExpandedCar& car : expansion.cars) trains.cars.push_back(car.name);
  trains.cars_per_train = static_cast<int>(expansion.cars.size() / train_names.size());
  // Mean deceleration per car: the named car-type bodies, or each car's heaviest body (its car body).
  if (q.passenger_bodies.empty())
    for (const ExpandedCar& car : expansion.cars) {
      const Body* heaviest = nullptr;
      for (const Body& b : model.bodies())
        if (b.car == car.name && (!heaviest || b.mass > heaviest->mass)) heaviest = &b;
      if (heaviest) trains.passenger_bodies.push_back(heaviest->name);
    }
  for (const std::string& b : q.passenger_bodies) {
    bool found = false;
    for (const ExpandedCar& car : expansion.cars)
      if (model.find_body(car.name + "." + b)) trains.passenger_bodies.push_back(car.name + "." + b), found = true;
    if (!found) fail_at(path, root["car_types"], "no car type has a body named '" + b + "' (from --passenger-bodies, which names car types' bodies)");
  }
  if (!q.survival_gauge.empty())
    for (const ExpandedCar& car : expansion.cars)
      if (model.find_body(car.name + "." + q.survival_gauge[0]) && model.find_body(car.name + "." + q.survival_gauge[1]))
        trains.gauges.push_back({car.name, car.name + "." + q.survival_gauge[0], car.name + "." + q.survival_gauge[1]});
  // Declared crush zones: a car type's (or interface type's) element name reaches every instance;
  // TYPE.NAME only the instances of car type TYPE (car types may name different zones alike).
  for (const std::string& entry : q.crush_zones) {
    const auto zone = crush_zone(entry);
    const auto dot = zone.first.find('.');
    const std::string type = dot == std::string::npos ? "" : zone.first.substr(0, dot);
    const std::string local = dot == std::string::npos ? zone.first : zone.first.substr(dot + 1);
    if (!type.empty() && !root["car_types"][type])
      fail_at(path, root["car_types"], "no car type '" + type + "' (from --crush-zones " + entry + "); its car types: " + keys_of(root["car_types"]));
    const auto ends_with_local = [&](const std::string& name) {
      return name.size() > local.size() && name.compare(name.size() - local.size() - 1, std::string::npos, "." + local) == 0;
    };
    bool found = false;
    for (const auto& e : model.elements()) {
      if (!ends_with_local(e->name())) continue;
      if (!type.empty()) {
        const auto car = std::find_if(expansion.cars.begin(), expansion.cars.end(),
                                      [&](const ExpandedCar& c) { return c.type == type && e->name() == c.name + "." + local; });
        if (car == expansion.cars.end()) continue;
      }
      trains.zones.push_back({e->name(), zone.second});
      found = true;
    }
    if (!found)
      fail_at(path, root["car_types"], "no element named '" + local + "' in " + (type.empty() ? "the car or interface types" : "car type " + type) +
                                           " (from --crush-zones)");
  }
  // Per train, its leading car's foremost wheels (wheel_rail) or rail supports (slider_joints on
  // ground: a bogie held on the rail), foremost along the train's direction of travel.
  const auto car_of = [&](int body) { return body == kGround ? std::string() : model.bodies()[static_cast<std::size_t>(body)].car; };
  for (const std::string& t : train_names) {
    const std::string lead_car = t + "." + first_car;
    const double ahead = t == striking ? 1.0 : -1.0;
    for (const char* kind : {"wheel_rail", "slider_joint"}) {
      std::vector<std::string> found;
      double foremost = -1e300;
      for (const auto& e : model.elements()) {
        if (e->type() != kind || e->points().size() != 2) continue;
        const int body = e->point(0).body == kGround ? e->point(1).body : e->point(0).body;
        if ((e->point(0).body != kGround && e->point(1).body != kGround) || car_of(body) != lead_car) continue;
        const double x = ahead * model.bodies()[static_cast<std::size_t>(body)].x;
        if (x > foremost + 1e-9) foremost = x, found.clear();
        if (std::abs(x - foremost) <= 1e-9) found.push_back(e->name());
      }
      auto& into = std::string(kind) == "wheel_rail" ? trains.wheels : trains.rail_supports;
      if (std::string(kind) == "slider_joint" && !trains.wheels.empty()) break;  // wheels judged by their lift
      into.insert(into.end(), found.begin(), found.end());
    }
  }
  if (trains.wheels.empty() && trains.rail_supports.empty())
    fail_at(path, root["car_types"], "the leading car " + first_car + " has neither wheel_rail elements nor slider_joints holding a "
                                     "body on the rail (points on ground): the override criterion needs the leading bogie's wheels");
  if (standing_train) {
    // What holds the two fronts together vertically: an anticlimber's interlock, a coupler_end's
    // face friction, a coupling's head friction or vertical spring.
    bool vertical = false;
    for (const YAML::Node& e : doc["elements"]) {
      if (!e["name"] || !starts_with(e["name"].Scalar(), "impact.")) continue;
      const std::string type = e["type"].Scalar();
      const auto positive = [&](const char* key) { return e[key] && e[key].as<double>() > 0.0; };
      if (is_anticlimber_type(type)) trains.interface_element = e["name"].Scalar();
      vertical = vertical || is_anticlimber_type(type) || (type == "coupler_end" && positive("friction")) ||
                 (type == "coupling" && (positive("friction") || positive("vertical_stiffness")));
    }
    if (!vertical && offset > 0.0)
      fail_at(path, root["interface_types"][interface],
              "interface type '" + interface + "' has no element that acts vertically between the fronts (an anticlimber's "
              "interlock, a coupler_end's friction, a coupling's friction or vertical_stiffness): the vertical offset cannot act "
              "(nothing holds the faces together vertically, so override cannot develop); give --interface naming one that has");
    if (trains.interface_element.empty())
      trains.interface_bodies = {striking + "." + first_car + "." + front_body_local, standing + "." + first_car + "." + front_body_local};
  }
  trains.front_body = striking + "." + first_car + "." + front_body_local;
  const Body& front = model.bodies()[static_cast<std::size_t>(*model.find_body(trains.front_body))];
  const double to_file = u.millimetre ? 1e3 : 1.0;  // the loaded model is in SI for mm-t-s-N files
  trains.front_x = front.x * to_file;
  trains.front_y = front.y * to_file;
  trains.face_x = 0.0;
  doc.remove("name");
  trains.model = doc;
  trains.striking_label = striking;
  trains.standing_label = standing;
  trains.header << "# Trains: " << train_name << " of " << path << " (" << trains.cars_per_train << " cars, car types";
  for (const ExpandedCar& car : expansion.cars)
    if (starts_with(car.name, striking + ".")) trains.header << " " << car.type << (car.reversed ? " (reversed)" : "");
  trains.header << ") as `" << striking << "`, its front (" << first_car << "." << leading << ") at x = 0"
                << (standing_train ? "; `" + standing + "` the same train facing -x, joined at impact (interface type " + interface + ")" : "")
                << ".\n# Expanded (railcrash expand): left out the model's own bodies and elements (the test's), its other trains and connections.\n";
}

/// True for a two-car template of the consist generator (consist.hpp): car1_* bodies and the
/// coupler_faces interface; any other model is read as a train unit (scenarios/train_unit.hpp).
bool is_two_car_template(const YAML::Node& root) {
  if (!root.IsMap() || !root["bodies"] || !root["bodies"].IsSequence() || !root["elements"] || !root["elements"].IsSequence()) return false;
  bool striking_car = false, coupler_faces = false;
  for (const YAML::Node& b : root["bodies"]) striking_car = striking_car || (b["name"] && starts_with(b["name"].as<std::string>(), "car1_"));
  for (const YAML::Node& e : root["elements"]) coupler_faces = coupler_faces || (e["name"] && e["name"].as<std::string>() == "coupler_faces");
  return striking_car && coupler_faces;
}

}  // namespace

std::string make_scenario_model(const ScenarioRequest& q) {
  if (q.category != "C-I" && q.category != "C-II" && q.category != "C-III" && q.category != "C-IV")
    refuse("--category " + q.category + " is not an EN 15227 crashworthiness design category; use C-I, C-II, C-III or C-IV");
  // "the obstacle is pushed aside rather than causing derailment" (railwaynews.net, scenario 4).
  if (q.number == 4)
    refuse("scenario 4 (a low obstacle) cannot be represented: the obstacle deflector's job is to push the obstacle "
           "sideways, out of the longitudinal-vertical plane this planar solver models");
  if (q.number < 1 || q.number > 4) refuse("EN 15227 defines scenarios 1 to 4; " + std::to_string(q.number) + " is not one of them");
  if (q.cars < 1) refuse("--cars must be at least 1");
  double speed_kmh = 36.0;  // [km/h] C-I, scenarios 1 and 2: sources in scenario/en15227.hpp
  if (q.speed) speed_kmh = required(q.speed, "--speed", "");
  else if (q.number == 3)
    refuse("missing --speed: scenario 3's speed depends on the category (up to 110 km/h) and no public source confirmed "
           "the value for " + q.category + "; give it in km/h");
  else if (q.category != "C-I")
    refuse("missing --speed: the public sources give the closing speed (36 km/h) for category C-I only; give " + q.category + "'s in km/h");
  if (q.number == 1 && !q.offset)
    refuse("missing --offset: the vertical offset between the two units [mm] (EN 15227 scenario 1; give 0 for none)");
  required(q.deceleration_limit, "--deceleration-limit", "the mean longitudinal deceleration limit of the passenger areas [g]");
  required(q.survival_limit, "--survival-space-limit", "the largest allowed crush of a car's survival space [mm]");
  if (q.number != 3) required(q.override_limit, "--override-limit", "the largest allowed vertical relative displacement at the interface [mm]");
  if (!q.survival_gauge.empty() && q.survival_gauge.size() != 2)
    refuse("--survival-gauge FRONT,REAR: give two bodies (without car1_ in a two-car template) at the ends of the survival space");
  if (q.number == 2) {
    check_crush_curve(q.buffer_curve, q.buffer_unloading_stiffness, "--buffer-curve", "--buffer-unloading-stiffness", "one side buffer's force-stroke curve");
    required(q.buffer_height, "--buffer-height", "the wagon's buffer centre height above the rail [mm]");
    if (!(q.wagon_mass > 0.0)) refuse("--wagon-mass must be positive");
  }
  if (q.number == 3) {
    check_crush_curve(q.obstacle_curve, q.obstacle_unloading_stiffness, "--obstacle-curve", "--obstacle-unloading-stiffness",
                      "the obstacle's force-crush characteristic");
    required(q.obstacle_height, "--obstacle-height", "the height of the obstacle's contact point above the rail [mm]");
    if (!(q.obstacle_mass > 0.0)) refuse("--obstacle-mass must be positive");
  }
  if (q.offset && *q.offset < 0.0) refuse("--offset must not be negative (the standing train is raised by it)");

  YAML::Node root;
  try {
    root = load_yaml_file(q.train_path, "train model");
  } catch (const YAML::Exception& e) {
    throw InputError(q.train_path + ": cannot read the train model: " + e.what());
  }
  if (q.passenger_bodies.empty() && !is_car_type_model(root))
    refuse("missing --passenger-bodies: the car bodies of the passenger area, as the train model names them (without car1_ in a "
           "two-car template), e.g. center_body");
  Trains trains;
  Units u;
  const double offset_mm = q.number == 1 ? *q.offset : 0.0;  // [mm]
  double closing_speed = 0.0;                                 // [length/time]
  if (is_car_type_model(root)) {
    u = Units::of(root["units"] ? root["units"].as<std::string>() : "");
    closing_speed = u.speed(speed_kmh);
    car_type_trains(q, root, u, closing_speed, u.length(offset_mm), trains);
  } else if (is_two_car_template(root)) {
    const Template t = read_template(q.train_path);
    u = t.units;
    closing_speed = u.speed(speed_kmh);
    template_trains(q, t, closing_speed, u.length(offset_mm), trains);
  } else {
    u = Units::of(root.IsMap() && root["units"] ? root["units"].as<std::string>() : "");
    closing_speed = u.speed(speed_kmh);
    unit_trains(q, read_train_unit(q.train_path, root), u, closing_speed, u.length(offset_mm), trains);
  }
  if (!trains.wheels.empty())
    required(q.wheel_lift_limit, "--wheel-lift-limit", "the largest allowed wheel lift of the leading bogies [mm]");
  YAML::Node model = trains.model;
  const double offset = u.length(offset_mm);
  std::ostringstream header;
  header << "# EN 15227 design collision scenario " << q.number << " (category " << q.category << "), generated by `railcrash scenario`\n"
         << "# from " << q.train_path << " (" << trains.cars_per_train << " car" << (trains.cars_per_train > 1 ? "s" : "") << " per train; include/railcrash/scenarios/en15227.hpp\n"
         << "# says how the model is built and which values come from which source).\n"
         << (q.number == 3 ? "# Speed " : "# Closing speed ") << speed_kmh << " km/h = " << closing_speed << " " << u.speed_name()
         << (q.speed ? " (--speed)" : " (36 km/h: C-I default, railwaynews.net 'Designed to Deform: EN 15227...', scenario "
                                      "1; railway-impact-simulator configs/en15227, scenarios 1 and 2)")
         << ".\n" << trains.header.str();
  if (q.number == 1) {
    header << "# Vertical offset " << *q.offset << " mm = " << offset << " " << u.length_name()
           << " (--offset, required input): the standing train and its rails are raised by it.\n"
           << "# Centre-of-mass frame: the striking train (" << trains.striking_label << ") at +" << closing_speed / 2 << ", the standing one ("
           << trains.standing_label << ") at -"
           << closing_speed / 2 << " " << u.speed_name() << ".\n";
  } else if (q.number == 2) {
    add_struck_body({"wagon", "wagon_buffers", q.wagon_mass, &q.buffer_curve, *q.buffer_unloading_stiffness, *q.buffer_height, 2}, u, trains);
    trains.interface_bodies = {trains.front_body, "wagon"};
    header << "# Wagon " << q.wagon_mass << " t (" << u.mass(q.wagon_mass) << u.mass_name()
           << "; 80 t: railwaynews.net, scenario 2) at rest on a frictionless slider; the train at " << closing_speed << " "
           << u.speed_name() << ".\n# Side buffers: two in parallel (wagon_buffers: twice one buffer's force), at "
           << *q.buffer_height << " mm above the rail (--buffer-height), force-stroke curve --buffer-curve, unloading "
           << *q.buffer_unloading_stiffness << " kN/mm per buffer (required inputs); they strike the train's front face ("
           << trains.front_body << ").\n";
  } else {
    add_struck_body({"obstacle", "obstacle_crush", q.obstacle_mass, &q.obstacle_curve, *q.obstacle_unloading_stiffness, *q.obstacle_height, 1},
                    u, trains);
    header << "# Obstacle " << q.obstacle_mass << " t (" << u.mass(q.obstacle_mass) << u.mass_name()
           << "; 15 t: railwaynews.net, scenario 3) at rest on a frictionless slider.\n"
           << "# Its force-crush characteristic --obstacle-curve, unloading " << *q.obstacle_unloading_stiffness
           << " kN/mm, contact point " << *q.obstacle_height << " mm above the rail (--obstacle-height): required inputs; it strikes the "
           << "train's front face (" << trains.front_body << ").\n# No interface: override is judged by the leading bogie's wheel lift.\n";
  }
  std::ostringstream name;
  name << "EN 15227 scenario " << q.number << " (" << q.category << "): " << trains.cars_per_train << "-car train"
       << (q.number == 1 ? " into an identical train" : q.number == 2 ? " into an 80 t wagon with side buffers" : " into a deformable obstacle")
       << ", built from " << q.train_path;
  model["name"] = name.str();
  if (model["description"]) model.remove("description");
  if (model["responses"]) model.remove("responses");  // the report's R1-R3 belong to its own two-car model
  if (q.t_end) model["simulation"]["t_end"] = *q.t_end;
  resolve_zone_strokes(model, q.train_path, u, trains);
  model["scenario"] = criteria_section(q, trains, u, closing_speed);

  YAML::Emitter emitter;
  emitter << model;
  return header.str() + emitter.c_str() + "\n";
}

}  // namespace railcrash
