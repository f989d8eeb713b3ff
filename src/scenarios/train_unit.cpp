// A train unit from any car model (scenario/train_unit.hpp says how its striking end is found).
#include "railcrash/scenarios/train_unit.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "railcrash/core/error.hpp"
#include "railcrash/model/element.hpp"
#include "railcrash/model/model.hpp"
#include "railcrash/model/model_io.hpp"
#include "railcrash/model/yaml_file.hpp"

namespace railcrash {
namespace {

struct WorldPoint {
  double x, y;  // [length]
};

WorldPoint world_point(const Model& model, const PointRef& point) {
  const Body& b = model.bodies()[static_cast<std::size_t>(point.body)];
  return {b.x + std::cos(b.angle) * point.sx - std::sin(b.angle) * point.sy, b.y + std::sin(b.angle) * point.sx + std::cos(b.angle) * point.sy};
}

bool is_vector_key(const std::string& key) {
  for (const char* k : {"position", "velocity", "at", "axis", "line_point", "line_normal", "circle_center"})
    if (key == k) return true;
  return false;
}

}  // namespace

YAML::Node transformed_node(const YAML::Node& node, const std::function<std::string(const std::string&, const std::string&)>& rename,
                            bool mirror, const std::string& key) {
  if (node.IsScalar()) {
    YAML::Node out = YAML::Clone(node);
    const std::string renamed = rename(key, node.Scalar());
    if (renamed != node.Scalar()) out = renamed;
    if (mirror && (key == "angle" || key == "angular_velocity")) out = -node.as<double>();  // pitch changes sign in the mirror
    return out;
  }
  if (node.IsSequence()) {
    YAML::Node out(YAML::NodeType::Sequence);
    for (const YAML::Node& item : node) out.push_back(transformed_node(item, rename, mirror));
    if (mirror && is_vector_key(key) && out.size() == 2) out[0] = -node[0].as<double>();
    out.SetStyle(node.Style());
    return out;
  }
  if (node.IsMap()) {
    YAML::Node out(YAML::NodeType::Map);
    for (const auto& item : node) out[item.first.Scalar()] = transformed_node(item.second, rename, mirror, item.first.Scalar());
    out.SetStyle(node.Style());
    return out;
  }
  return YAML::Clone(node);
}

void ScenarioModelReader::fail(const YAML::Node& node, const std::string& message) const {
  YamlReader::fail(node, "scenario train model: " + message);
}

void TrainUnit::fail(const YAML::Node& node, const std::string& what) const { ScenarioModelReader(path).fail(node, what); }

YAML::Node TrainUnit::body(const std::string& name, const std::string& option) const {
  for (const YAML::Node& b : root["bodies"])
    if (b["name"] && b["name"].as<std::string>() == name) return b;
  fail(root["bodies"], "no body named '" + name + "' (from " + option + ", which names the train model's bodies)");
}

TrainUnit read_train_unit(const std::string& path, const YAML::Node& root) {
  TrainUnit unit;
  unit.path = path;
  unit.root = root;
  const Model model = load_model(path).model;
  const auto car_of = [&](int body) { return body == kGround ? std::string() : model.bodies()[static_cast<std::size_t>(body)].car; };
  bool any_car = false;
  for (const Body& b : model.bodies()) any_car = any_car || !b.car.empty();
  if (!any_car)
    unit.fail(root["bodies"], "no car: a scenario train is built from the cars its bodies declare ('car: NAME' on each body of a car, "
                              "as in models/barrier/two_car_barrier.yaml), or from a two-car template with car1_*/car2_* bodies "
                              "(models/report/final_two_car.yaml)");
  double foremost = -1e300;  // [length]
  const Element* front_crush = nullptr;
  for (const auto& e : model.elements()) {
    if (e->output_with_role(OutputRole::Crush).empty() || e->points().size() != 2) continue;
    const std::string car = car_of(e->point(0).body);
    if (car.empty() || car != car_of(e->point(1).body)) continue;
    for (int p = 0; p < 2; ++p) {
      const double x = world_point(model, e->point(p)).x;
      if (x > foremost) {
        foremost = x;
        front_crush = e.get();
        unit.front_body = model.bodies()[static_cast<std::size_t>(e->point(p).body)].name;
      }
    }
  }
  if (!front_crush)
    unit.fail(root["elements"], "no front end: the scenario needs a crush element at the striking end (an element with a crush "
                                "output, e.g. a crush_spring, between the leading car's body and its front-end body, both declaring "
                                "the car; the train travels towards +x), or a two-car template (car1_*/car2_* bodies joined by coupler_faces, "
                                "as models/report/final_two_car.yaml)");
  unit.front_crush = front_crush->name();
  const int front_index = *model.find_body(unit.front_body);
  const Body& front = model.bodies()[static_cast<std::size_t>(front_index)];
  unit.striking_car = front.car;
  unit.front_body_x = front.x;
  unit.front_body_y = front.y;
  unit.face_x = -1e300;
  for (const auto& e : model.elements()) {
    if (e->type() == "contact") unit.fixed_surface_contacts.push_back(e->name());
    for (const PointRef& p : e->points())
      if (p.body == front_index) {
        const WorldPoint w = world_point(model, p);
        if (w.x > unit.face_x) unit.face_x = w.x, unit.face_y = w.y;
      }
  }
  double foremost_wheel = -1e300;  // [length] x of the striking car's foremost wheel-carrying body
  for (const auto& e : model.elements()) {
    if (e->type() != "wheel_rail" || car_of(e->point(0).body) != unit.striking_car) continue;
    const double x = model.bodies()[static_cast<std::size_t>(e->point(0).body)].x;
    if (x > foremost_wheel + 1e-9) {
      foremost_wheel = x;
      unit.leading_wheels.clear();
    }
    if (std::abs(x - foremost_wheel) <= 1e-9) unit.leading_wheels.push_back(e->name());
  }
  if (unit.leading_wheels.empty())
    unit.fail(root["elements"], "no wheel_rail elements on the striking car '" + unit.striking_car +
                                    "': the wheel lift-off criterion needs the leading bogie's wheels");
  return unit;
}

void append_unit(const TrainUnit& unit, const UnitPlacement& placement, YAML::Node& bodies, YAML::Node& elements) {
  std::map<std::string, bool> body_names;
  for (const YAML::Node& b : unit.root["bodies"]) body_names[b["name"].as<std::string>()] = true;
  const auto rename = [&](const std::string& key, const std::string& scalar) {
    if (key == "name" || key == "car" || (key == "body" && body_names.count(scalar))) return placement.prefix + scalar;
    return scalar;
  };
  const double sign = placement.mirrored ? -1.0 : 1.0;
  for (const YAML::Node& b : unit.root["bodies"]) {
    YAML::Node copy = transformed_node(b, rename, placement.mirrored);
    copy["position"] = flow_pair(sign * (b["position"][0].as<double>() - unit.face_x), b["position"][1].as<double>() + placement.raise);
    copy["velocity"] = flow_pair(sign * placement.velocity, 0.0);
    bodies.push_back(copy);
  }
  for (const YAML::Node& e : unit.root["elements"]) {
    const std::string name = e["name"].as<std::string>();
    if (std::find(unit.fixed_surface_contacts.begin(), unit.fixed_surface_contacts.end(), name) != unit.fixed_surface_contacts.end())
      continue;
    YAML::Node copy = transformed_node(e, rename, placement.mirrored);
    if (copy["type"].as<std::string>() == "wheel_rail")
      copy["rail_height"] = (e["rail_height"] ? e["rail_height"].as<double>() : 0.0) + placement.raise;
    for (YAML::Node point : copy["points"])  // points fixed on the ground are world positions
      if (point["body"] && point["body"].as<std::string>() == "ground")
        point["at"] = flow_pair(sign * (point["at"][0].as<double>() * sign - unit.face_x), point["at"][1].as<double>() + placement.raise);
    elements.push_back(copy);
  }
}

}  // namespace railcrash
