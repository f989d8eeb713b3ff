// EN 15227 design collision scenarios (scenario/en15227.hpp says what is built and from which sources).
#include "railcrash/scenario/en15227.hpp"

#include <yaml-cpp/yaml.h>

#include <cctype>
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "railcrash/consist.hpp"
#include "railcrash/element.hpp"
#include "railcrash/error.hpp"
#include "railcrash/model.hpp"
#include "railcrash/model_io.hpp"
#include "railcrash/scenario/train_unit.hpp"
#include "railcrash/yaml_file.hpp"

namespace railcrash {
namespace {

constexpr double kInch = 0.0254;              // [m]
constexpr double kPoundForce = 4.4482216152605;  // [N]
constexpr double kPoundMass = 0.45359237;     // [kg]
constexpr double kStandardGravitySI = 9.80665;  // [m/s^2]
constexpr double kStandardGravityInch = 386.088;  // [in/s^2] the value results.hpp's g in in-lbf-s models uses

/// Conversions from the command's units (km/h, mm, kN, t) to the model's.
struct Units {
  bool inch_pound = false;
  double length(double mm) const { return inch_pound ? mm / 25.4 : mm * 1e-3; }
  double speed(double kmh) const { return inch_pound ? kmh / 3.6 / kInch : kmh / 3.6; }
  double force(double kn) const { return inch_pound ? kn * 1e3 / kPoundForce : kn * 1e3; }
  double acceleration(double g) const { return g * (inch_pound ? kStandardGravityInch : kStandardGravitySI); }
  const char* length_name() const { return inch_pound ? "in" : "m"; }
  const char* speed_name() const { return inch_pound ? "in/s" : "m/s"; }
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

  [[noreturn]] void fail(const YAML::Node& node, const std::string& what) const {
    const int line = node.IsDefined() && !node.Mark().is_null() ? node.Mark().line + 1 : 0;
    throw InputError(SourceLocation{path, line}.prefix() + "scenario train model: " + what);
  }
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
  const Model model = load_model(path);
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
    if (copy["type"].as<std::string>() == "anticlimber") copy["initial_misalignment"] = 0.0;
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
  std::vector<std::string> excluded;            // crush elements that are not survival space
  std::vector<std::string> wheels;              // the leading bogies' wheel_rail elements
  std::string interface_element;                // the anticlimber between two template-built trains
  std::vector<std::string> interface_bodies;    // otherwise the two bodies meeting at the interface
  std::string front_body;                       // the striking train's front (the struck body meets it)
  double front_x = 0.0, front_y = 0.0;          // [length] its centre of gravity
  double face_x = 0.0;                          // [length] the front face
  int cars_per_train = 1;
  std::ostringstream header;                    // the model file's comment lines
};

/// Refuses a --crush-zones name that is no element of the train model.
void check_crush_zones(const YAML::Node& root, const std::string& path, const std::vector<std::string>& names, const std::string& prefix) {
  for (const std::string& name : names) {
    bool found = false;
    for (const YAML::Node& e : root["elements"]) found = found || (e["name"] && e["name"].as<std::string>() == prefix + name);
    if (!found)
      throw InputError(path + ": scenario train model: no element named '" + prefix + name + "' (from --crush-zones, which names the " +
                       "crush elements of a car whose crush is allowed" + (prefix.empty() ? "" : ", without the car1_ prefix") + ")");
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
    add_names(trains.excluded, {prefix}, q.crush_zones);
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

/// Trains from a model whose bodies declare their cars (scenario/train_unit.hpp): the striking
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
  add_names(trains.excluded, prefixes, q.crush_zones);
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
                << "element " << unit.front_crush << " (scenario/train_unit.hpp).\n# Left out (the test's fixed surfaces):";
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
    faces["points"] = two_points("s_" + unit.front_body, flow_pair(0.0, unit.face_y - unit.front_body_y), "t_" + unit.front_body,
                                 flow_pair(0.0, unit.face_y - unit.front_body_y));
    elements.push_back(faces);
    trains.interface_bodies = {"s_" + unit.front_body, "t_" + unit.front_body};
    trains.header << "# The front faces meet at front_faces (coupler_end, uncoupled): " << *q.face_stiffness << " kN/mm per face (--face-stiffness), "
                  << *q.face_height << " mm high (--face-height), required inputs.\n";
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
  const double mass_kg = struck.mass * 1e3;
  YAML::Node body(YAML::NodeType::Map);
  body["name"] = struck.name;
  if (u.inch_pound) body["weight"] = mass_kg / kPoundMass;  // [lbf]
  else body["mass"] = mass_kg;
  // Its rotation is locked by the slider, so the inertia only has to be positive (Euler's
  // penalty joints need one): that of the mass at 1 m.
  const double mass_model = u.inch_pound ? mass_kg / kPoundMass / kStandardGravityInch : mass_kg;
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

/// The model's `scenario:` section (scenario/criteria.hpp).
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
  if (q.number != 3) {
    override_node["limit"] = u.length(*q.override_limit);
    override_node["source"] = "--override-limit " + number_text(*q.override_limit) + " mm: " + input;
  }
  override_node["wheel_lift_limit"] = u.length(*q.wheel_lift_limit);
  override_node["wheel_lift_source"] = "--wheel-lift-limit " + number_text(*q.wheel_lift_limit) + " mm: " + input;
  override_node["wheels"] = flow_list(trains.wheels);
  s["override"] = override_node;
  return s;
}

/// True for a two-car template of the consist generator (consist.hpp): car1_* bodies and the
/// coupler_faces interface; any other model is read as a train unit (scenario/train_unit.hpp).
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
  required(q.wheel_lift_limit, "--wheel-lift-limit", "the largest allowed wheel lift of the leading bogies [mm]");
  if (q.passenger_bodies.empty())
    refuse("missing --passenger-bodies: the car bodies of the passenger area, as the train model names them (without car1_ in a "
           "two-car template), e.g. center_body");
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
  Trains trains;
  Units u;
  const double offset_mm = q.number == 1 ? *q.offset : 0.0;  // [mm]
  double closing_speed = 0.0;                                 // [length/time]
  if (is_two_car_template(root)) {
    const Template t = read_template(q.train_path);
    u = t.units;
    closing_speed = u.speed(speed_kmh);
    template_trains(q, t, closing_speed, u.length(offset_mm), trains);
  } else {
    const std::string units = root.IsMap() && root["units"] ? root["units"].as<std::string>() : "";
    u.inch_pound = units == "in-lbf-s";
    closing_speed = u.speed(speed_kmh);
    unit_trains(q, read_train_unit(q.train_path, root), u, closing_speed, u.length(offset_mm), trains);
  }
  YAML::Node model = trains.model;
  const double offset = u.length(offset_mm);
  std::ostringstream header;
  header << "# EN 15227 design collision scenario " << q.number << " (category " << q.category << "), generated by `railcrash scenario`\n"
         << "# from " << q.train_path << " (" << trains.cars_per_train << " car" << (trains.cars_per_train > 1 ? "s" : "") << " per train; include/railcrash/scenario/en15227.hpp\n"
         << "# says how the model is built and which values come from which source).\n"
         << (q.number == 3 ? "# Speed " : "# Closing speed ") << speed_kmh << " km/h = " << closing_speed << " " << u.speed_name()
         << (q.speed ? " (--speed)" : " (36 km/h: C-I default, railwaynews.net 'Designed to Deform: EN 15227...', scenario "
                                      "1; railway-impact-simulator configs/en15227, scenarios 1 and 2)")
         << ".\n" << trains.header.str();
  if (q.number == 1) {
    header << "# Vertical offset " << *q.offset << " mm = " << offset << " " << u.length_name()
           << " (--offset, required input): the standing train and its rails are raised by it.\n"
           << "# Centre-of-mass frame: the striking train (s*) at +" << closing_speed / 2 << ", the standing one (t*) at -"
           << closing_speed / 2 << " " << u.speed_name() << ".\n";
  } else if (q.number == 2) {
    add_struck_body({"wagon", "wagon_buffers", q.wagon_mass, &q.buffer_curve, *q.buffer_unloading_stiffness, *q.buffer_height, 2}, u, trains);
    trains.interface_bodies = {trains.front_body, "wagon"};
    const double mass_kg = q.wagon_mass * 1e3;
    header << "# Wagon " << q.wagon_mass << " t (" << (u.inch_pound ? mass_kg / kPoundMass : mass_kg) << (u.inch_pound ? " lbf weight" : " kg")
           << "; 80 t: railwaynews.net, scenario 2) at rest on a frictionless slider; the train at " << closing_speed << " "
           << u.speed_name() << ".\n# Side buffers: two in parallel (wagon_buffers: twice one buffer's force), at "
           << *q.buffer_height << " mm above the rail (--buffer-height), force-stroke curve --buffer-curve, unloading "
           << *q.buffer_unloading_stiffness << " kN/mm per buffer (required inputs); they strike the train's front face ("
           << trains.front_body << ").\n";
  } else {
    add_struck_body({"obstacle", "obstacle_crush", q.obstacle_mass, &q.obstacle_curve, *q.obstacle_unloading_stiffness, *q.obstacle_height, 1},
                    u, trains);
    const double mass_kg = q.obstacle_mass * 1e3;
    header << "# Obstacle " << q.obstacle_mass << " t (" << (u.inch_pound ? mass_kg / kPoundMass : mass_kg) << (u.inch_pound ? " lbf weight" : " kg")
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
  model["scenario"] = criteria_section(q, trains, u, closing_speed);

  YAML::Emitter emitter;
  emitter << model;
  return header.str() + emitter.c_str() + "\n";
}

}  // namespace railcrash
