// EN 15227 design collision scenarios (scenario/en15227.hpp says what is built and from which sources).
#include "railcrash/scenario/en15227.hpp"

#include <yaml-cpp/yaml.h>

#include <cctype>
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "railcrash/consist.hpp"
#include "railcrash/error.hpp"
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
YAML::Node mirrored(const YAML::Node& node, const std::string& key = "") {
  if (node.IsScalar()) {
    YAML::Node out = YAML::Clone(node);
    if (starts_with(node.Scalar(), "car1_")) out = "car2_" + node.Scalar().substr(5);
    return out;
  }
  if (node.IsSequence()) {
    static const char* kVectors[] = {"position", "velocity", "at", "axis", "line_point", "line_normal", "circle_center"};
    bool vector = false;
    for (const char* k : kVectors) vector = vector || key == k;
    YAML::Node out(YAML::NodeType::Sequence);
    for (const YAML::Node& item : node) out.push_back(mirrored(item));
    if (vector && out.size() == 2) out[0] = -node[0].as<double>();
    out.SetStyle(node.Style());
    return out;
  }
  if (node.IsMap()) {
    YAML::Node out(YAML::NodeType::Map);
    for (const auto& item : node) out[item.first.Scalar()] = mirrored(item.second, item.first.Scalar());
    out.SetStyle(node.Style());
    return out;
  }
  return YAML::Clone(node);
}

struct Template {
  std::string path;
  YAML::Node root;
  Units units;
  std::string anticlimber;   // interface anticlimber's name ("" if none)
  YAML::Node anticlimber_node;
  std::vector<std::string> leading_wheels;  // car1_ wheel_rail elements on the foremost wheel-carrying body

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
  bool coupler = false, striking_car = false;
  for (const YAML::Node& b : t.root["bodies"]) striking_car = striking_car || starts_with(b["name"].as<std::string>(), "car1_");
  if (!striking_car)
    t.fail(t.root["bodies"], "no striking car: the scenario builds its trains from the bodies named car1_* (the car at x < 0 "
                             "whose front faces x = 0), as in models/report/final_two_car.yaml");
  double foremost = -1e300;
  std::map<std::string, double> body_x;
  for (const YAML::Node& b : t.root["bodies"]) body_x[b["name"].as<std::string>()] = b["position"][0].as<double>();
  for (const YAML::Node& e : t.root["elements"]) {
    const std::string name = e["name"].as<std::string>(), type = e["type"] ? e["type"].as<std::string>() : "";
    const bool interface = !starts_with(name, "car1_") && !starts_with(name, "car2_");
    if (interface && type == "coupler_end" && name == "coupler_faces") coupler = true;
    if (interface && type == "anticlimber") {
      t.anticlimber = name;
      t.anticlimber_node = e;
    }
    if (starts_with(name, "car1_") && type == "wheel_rail") {
      const double x = body_x[e["points"][0]["body"].as<std::string>()];
      if (x > foremost + 1e-9) {
        foremost = x;
        t.leading_wheels.clear();
      }
      if (std::abs(x - foremost) <= 1e-9) t.leading_wheels.push_back(name);
    }
  }
  if (!coupler)
    t.fail(t.root["elements"], "no coupler: the trains meet at an interface element 'coupler_faces' of type coupler_end "
                               "(car1_coupler to car2_coupler), which the consist generator needs");
  if (t.anticlimber.empty())
    t.fail(t.root["elements"], "no front end: the override criterion needs the interface anticlimber (an element of type "
                               "anticlimber between car1_front_end and car2_front_end)");
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

/// Survival-space gauges, passenger bodies and leading wheels of the generated model.
YAML::Node criteria_section(const ScenarioRequest& q, const Template& t, const Units& u, double closing_speed, bool with_standing_train,
                            const YAML::Node& override_bodies) {
  const std::string input = "required input (not confirmed from a public source)";
  YAML::Node s(YAML::NodeType::Map);
  s["standard"] = "EN 15227";
  s["number"] = q.number;
  s["category"] = q.category;
  s["closing_speed"] = closing_speed;
  std::vector<std::string> trains{"s"};
  if (with_standing_train) trains.push_back("t");
  YAML::Node deceleration(YAML::NodeType::Map);
  deceleration["limit"] = u.acceleration(*q.deceleration_limit);
  deceleration["cfc"] = 60;
  deceleration["source"] = "--deceleration-limit " + number_text(*q.deceleration_limit) + " g: " + input;
  YAML::Node bodies(YAML::NodeType::Sequence), gauges(YAML::NodeType::Sequence), wheels(YAML::NodeType::Sequence);
  for (const std::string& train : trains)
    for (int k = 1; k <= q.cars; ++k) {
      const std::string car = train + std::to_string(k);
      for (const std::string& b : q.passenger_bodies) bodies.push_back(car + "_" + b);
      YAML::Node gauge(YAML::NodeType::Map);
      gauge["name"] = car;
      gauge["front"] = car + "_" + q.survival_gauge[0];
      gauge["rear"] = car + "_" + q.survival_gauge[1];
      gauge.SetStyle(YAML::EmitterStyle::Flow);
      gauges.push_back(gauge);
    }
  bodies.SetStyle(YAML::EmitterStyle::Flow);
  deceleration["bodies"] = bodies;
  s["mean_deceleration"] = deceleration;
  YAML::Node survival(YAML::NodeType::Map);
  survival["limit"] = u.length(*q.survival_limit);
  survival["source"] = "--survival-space-limit " + number_text(*q.survival_limit) + " mm: " + input;
  survival["gauges"] = gauges;
  s["survival_space"] = survival;
  YAML::Node override_node(YAML::NodeType::Map);
  if (override_bodies.IsSequence()) override_node["bodies"] = override_bodies;
  else override_node["interface"] = t.anticlimber;
  override_node["limit"] = u.length(*q.override_limit);
  override_node["source"] = "--override-limit " + number_text(*q.override_limit) + " mm: " + input;
  override_node["wheel_lift_limit"] = u.length(*q.wheel_lift_limit);
  override_node["wheel_lift_source"] = "--wheel-lift-limit " + number_text(*q.wheel_lift_limit) + " mm: " + input;
  for (const std::string& train : trains)
    for (const std::string& w : t.leading_wheels) wheels.push_back(train + "1_" + w.substr(5));
  wheels.SetStyle(YAML::EmitterStyle::Flow);
  override_node["wheels"] = wheels;
  s["override"] = override_node;
  return s;
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

}  // namespace

std::string make_scenario_model(const ScenarioRequest& q) {
  if (q.category != "C-I" && q.category != "C-II" && q.category != "C-III" && q.category != "C-IV")
    refuse("--category " + q.category + " is not an EN 15227 crashworthiness design category; use C-I, C-II, C-III or C-IV");
  if (q.number == 3)
    refuse("scenario 3 (a large deformable obstacle at a level crossing) is not generated: the standard's reference obstacle "
           "(its mass distribution, geometry, height and force-deformation characteristic) could not be confirmed from a public "
           "source, and it would have to be invented");
  // "the obstacle is pushed aside rather than causing derailment" (railwaynews.net, scenario 4).
  if (q.number == 4)
    refuse("scenario 4 (a low obstacle) cannot be represented: the obstacle deflector's job is to push the obstacle "
           "sideways, out of the longitudinal-vertical plane this planar solver models");
  if (q.number != 1 && q.number != 2) refuse("EN 15227 defines scenarios 1 to 4; " + std::to_string(q.number) + " is not one of them");
  if (q.cars < 1) refuse("--cars must be at least 1");
  const Template t = read_template(q.train_path);
  const Units& u = t.units;
  double speed_kmh = 36.0;  // [km/h] C-I, scenarios 1 and 2: sources in scenario/en15227.hpp
  if (q.speed) speed_kmh = required(q.speed, "--speed", "");
  else if (q.category != "C-I")
    refuse("missing --speed: the public sources give the closing speed (36 km/h) for category C-I only; give " + q.category + "'s in km/h");
  if (q.number == 1 && !q.offset)
    refuse("missing --offset: the vertical offset between the two units [mm] (EN 15227 scenario 1; give 0 for none)");
  required(q.deceleration_limit, "--deceleration-limit", "the mean longitudinal deceleration limit of the passenger areas [g]");
  required(q.survival_limit, "--survival-space-limit", "the largest allowed shortening of a car's survival space [mm]");
  required(q.override_limit, "--override-limit", "the largest allowed vertical relative displacement at the interface [mm]");
  required(q.wheel_lift_limit, "--wheel-lift-limit", "the largest allowed wheel lift of the leading bogies [mm]");
  if (q.passenger_bodies.empty())
    refuse("missing --passenger-bodies: the car bodies of the passenger area, as the template names them without car1_ (e.g. center_body)");
  if (q.survival_gauge.size() != 2)
    refuse("missing --survival-gauge FRONT,REAR: the two template bodies (without car1_) at the ends of the survival space "
           "(e.g. bolster_body,rear_body)");
  for (const std::string& b : q.passenger_bodies) t.body("car1_" + b, "--passenger-bodies");
  for (const std::string& b : q.survival_gauge) t.body("car1_" + b, "--survival-gauge");
  if (q.number == 2) {
    if (q.buffer_curve.size() < 2) refuse("missing --buffer-curve: one side buffer's force-stroke curve 'mm:kN,mm:kN,...' (at least two points)");
    required(q.buffer_unloading_stiffness, "--buffer-unloading-stiffness", "one side buffer's unloading stiffness [kN/mm]");
    required(q.buffer_height, "--buffer-height", "the wagon's buffer centre height above the rail [mm]");
    if (!(q.wagon_mass > 0.0)) refuse("--wagon-mass must be positive");
    // The crush_spring unloads at the unloading stiffness from wherever it is on the curve, and
    // stores P^2 / (2 unloading stiffness): below the curve's steepest slope it would give back
    // more energy than the buffer took.
    double steepest = 0.0;  // [kN/mm]
    for (std::size_t k = 1; k < q.buffer_curve.size(); ++k) {
      const double stroke = q.buffer_curve[k].first - q.buffer_curve[k - 1].first;
      if (!(stroke > 0.0)) refuse("--buffer-curve: the strokes must increase (point " + std::to_string(k + 1) + ")");
      steepest = std::max(steepest, (q.buffer_curve[k].second - q.buffer_curve[k - 1].second) / stroke);
    }
    if (*q.buffer_unloading_stiffness < steepest * (1.0 - 1e-9))
      refuse("--buffer-unloading-stiffness " + number_text(*q.buffer_unloading_stiffness) + " kN/mm is below the curve's steepest slope " +
             number_text(steepest) + " kN/mm: unloading would give back more energy than the buffer took; give at least that");
  }
  if (q.offset && *q.offset < 0.0) refuse("--offset must not be negative (the standing train is raised by it)");

  const YAML::Node pair_template = identical_pair(t);
  YAML::Node model = YAML::Load(make_consist_model(pair_template, q.train_path, q.cars));
  const double closing_speed = u.speed(speed_kmh);  // [length/time]
  const double offset = q.number == 1 ? u.length(*q.offset) : 0.0;
  std::ostringstream header;
  header << "# EN 15227 design collision scenario " << q.number << " (category " << q.category << "), generated by `railcrash scenario`\n"
         << "# from " << q.train_path << " (" << q.cars << " car" << (q.cars > 1 ? "s" : "") << " per train; include/railcrash/scenario/en15227.hpp\n"
         << "# says how the model is built and which values come from which source).\n"
         << "# Closing speed " << speed_kmh << " km/h = " << closing_speed << " " << u.speed_name()
         << (q.speed ? " (--speed)" : " (36 km/h: C-I default, railwaynews.net 'Designed to Deform: EN 15227...', scenario "
                                      "1; railway-impact-simulator configs/en15227, scenarios 1 and 2)")
         << ".\n";

  YAML::Node bodies = model["bodies"];
  YAML::Node override_bodies;
  if (q.number == 1) {
    header << "# Vertical offset " << *q.offset << " mm = " << offset << " " << u.length_name()
           << " (--offset, required input): the standing train and its rails are raised by it.\n"
           << "# Centre-of-mass frame: the striking train (s*) at +" << closing_speed / 2 << ", the standing one (t*) at -"
           << closing_speed / 2 << " " << u.speed_name() << ".\n";
    for (YAML::Node b : bodies) {
      const bool striking = !is_standing(b["name"].as<std::string>());
      b["velocity"] = flow_pair(striking ? closing_speed / 2 : -closing_speed / 2, 0.0);
      if (!striking) b["position"] = flow_pair(b["position"][0].as<double>(), b["position"][1].as<double>() + offset);
    }
    for (YAML::Node e : model["elements"])
      if (e["type"].as<std::string>() == "wheel_rail" && is_standing(e["name"].as<std::string>()))
        e["rail_height"] = (e["rail_height"] ? e["rail_height"].as<double>() : 0.0) + offset;
  } else {
    // Scenario 2: the striking train alone, at the closing speed, against the wagon at rest.
    YAML::Node kept_bodies(YAML::NodeType::Sequence), kept_elements(YAML::NodeType::Sequence);
    for (YAML::Node b : bodies)
      if (!is_standing(b["name"].as<std::string>())) {
        b["velocity"] = flow_pair(closing_speed, 0.0);
        kept_bodies.push_back(b);
      }
    for (const YAML::Node& e : model["elements"])
      if (!touches_standing_train(e["points"])) kept_elements.push_back(e);
    // The anticlimber's face on the train: the buffers strike there.
    const YAML::Node face = t.anticlimber_node["points"][0];
    const std::string front_body = "s1_" + face["body"].as<std::string>().substr(5);
    const YAML::Node front = t.body(face["body"].as<std::string>());
    const double face_x = front["position"][0].as<double>() + face["at"][0].as<double>();  // [length]
    const double height = u.length(*q.buffer_height);                                       // [length]
    // [length] the buffer force acts between the train's face and a wagon point 100 m ahead: the
    // buffer heads slide on each other, so the force stays within 1/100 rad of horizontal for
    // each metre of vertical relative displacement.
    const double anchor = u.length(100000.0);
    const double wagon_mass_kg = q.wagon_mass * 1e3;
    YAML::Node wagon(YAML::NodeType::Map);
    wagon["name"] = "wagon";
    if (u.inch_pound) wagon["weight"] = wagon_mass_kg / kPoundMass;  // [lbf]
    else wagon["mass"] = wagon_mass_kg;
    // Its rotation is locked by the slider, so the inertia only has to be positive (Euler's
    // penalty joints need one): that of the mass at 1 m.
    const double wagon_mass_model = u.inch_pound ? wagon_mass_kg / kPoundMass / kStandardGravityInch : wagon_mass_kg;
    const double radius = u.length(1000.0);  // [length] the wagon's c.g. 1 m ahead of its buffer faces
    wagon["inertia"] = wagon_mass_model * radius * radius;
    wagon["position"] = flow_pair(face_x + radius, height);
    wagon.SetStyle(YAML::EmitterStyle::Flow);
    kept_bodies.push_back(wagon);
    YAML::Node slider(YAML::NodeType::Map);
    slider["name"] = "wagon_on_track";
    slider["type"] = "slider_joint";
    slider["axis"] = flow_pair(1, 0);
    slider["points"] = two_points("ground", flow_pair(face_x + radius, height), "wagon", flow_pair(0, 0));
    kept_elements.push_back(slider);
    YAML::Node buffers(YAML::NodeType::Map);
    buffers["name"] = "wagon_buffers";
    buffers["type"] = "crush_spring";
    YAML::Node curve(YAML::NodeType::Sequence);
    for (const auto& [stroke, force] : q.buffer_curve) curve.push_back(flow_pair(u.length(stroke), 2.0 * u.force(force)));
    buffers["curve"] = curve;
    buffers["unloading_stiffness"] = 2.0 * u.force(*q.buffer_unloading_stiffness) / u.length(1.0);
    buffers["free_length"] = anchor;
    buffers["points"] = two_points(front_body, flow_pair(face_x - front["position"][0].as<double>(), height - front["position"][1].as<double>()),
                                   "wagon", flow_pair(anchor - radius, 0));
    kept_elements.push_back(buffers);
    model["bodies"] = kept_bodies;
    model["elements"] = kept_elements;
    override_bodies = YAML::Node(YAML::NodeType::Sequence);
    override_bodies.push_back(front_body);
    override_bodies.push_back("wagon");
    override_bodies.SetStyle(YAML::EmitterStyle::Flow);
    header << "# Wagon " << q.wagon_mass << " t (" << (u.inch_pound ? wagon_mass_kg / kPoundMass : wagon_mass_kg)
           << (u.inch_pound ? " lbf weight" : " kg")
           << "; 80 t: railwaynews.net, scenario 2) at rest on a frictionless slider; the train at " << closing_speed << " "
           << u.speed_name() << ".\n# Side buffers: two in parallel (wagon_buffers: twice one buffer's force), at "
           << *q.buffer_height << " mm above the rail (--buffer-height), force-stroke curve --buffer-curve, unloading "
           << *q.buffer_unloading_stiffness << " kN/mm per buffer (required inputs); they strike the train's anticlimber face.\n";
  }
  std::ostringstream name;
  name << "EN 15227 scenario " << q.number << " (" << q.category << "): " << q.cars << "-car train"
       << (q.number == 1 ? " into an identical train" : " into an 80 t wagon with side buffers") << ", built from " << q.train_path;
  model["name"] = name.str();
  if (model["description"]) model.remove("description");
  if (model["responses"]) model.remove("responses");  // the report's R1-R3 belong to its own two-car model
  if (q.t_end) model["simulation"]["t_end"] = *q.t_end;
  model["scenario"] = criteria_section(q, t, u, closing_speed, q.number == 1, override_bodies);

  YAML::Emitter emitter;
  emitter << model;
  return header.str() + emitter.c_str() + "\n";
}

}  // namespace railcrash
