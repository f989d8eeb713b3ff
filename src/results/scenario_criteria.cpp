// Scenario criteria: the model's `scenario:` section and the evaluation (results/scenario_criteria.hpp).
#include "railcrash/results/scenario_criteria.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>

#include "railcrash/core/error.hpp"
#include "railcrash/model/model.hpp"
#include "railcrash/model/yaml_reader.hpp"
#include "railcrash/results/cfc_filter.hpp"
#include "railcrash/results/crash_pulse.hpp"
#include "railcrash/results/results.hpp"
#include "railcrash/solver/dae_system.hpp"
#include "railcrash/solver/initial_conditions.hpp"

namespace railcrash {
namespace {

/// Reads the model's `scenario:` section (the shared checks: YamlReader; messages "scenario: ..."
/// through the model reader's fail, which names the file and line or the setting). Its required,
/// text and positive keep the section's own wording ("missing 'KEY'", "must be a word or a quoted
/// text", "must be a positive number").
class SectionReader : public YamlReader {
 public:
  SectionReader(const Model& model, const SectionFail& fail) : YamlReader(model.file), model_(model), fail_(fail) {}

  [[noreturn]] void fail(const YAML::Node& node, const std::string& message) const override {
    fail_(node, "scenario: " + message);
    throw InputError("scenario: " + message);  // fail_ throws; this keeps the promise of [[noreturn]]
  }

  YAML::Node required(const YAML::Node& map, const std::string& key, const std::string& context) const {
    const YAML::Node node = map[key];
    if (!node) fail(map, context + ": missing '" + key + "'");
    return node;
  }

  std::string text(const YAML::Node& node, const std::string& what) const {
    if (!node.IsScalar() || node.Scalar().empty()) fail(node, what + " must be a word or a quoted text");
    return node.Scalar();
  }

  double positive(const YAML::Node& node, const std::string& what) const {
    double value = 0.0;
    try {
      value = node.as<double>();
    } catch (const YAML::Exception&) {
      fail(node, what + " must be a number");
    }
    if (!(value > 0.0) || !std::isfinite(value)) fail(node, what + " must be a positive number");
    return value;
  }

  std::string body(const YAML::Node& node, const std::string& what) const {
    const std::string name = text(node, what);
    if (!model_.find_body(name)) fail(node, what + ": no body named '" + name + "' in the model");
    return name;
  }

  std::string element(const YAML::Node& node, const std::string& what, const std::string& type) const {
    const std::string name = text(node, what);
    for (const auto& e : model_.elements())
      if (e->name() == name) {
        if (e->type() != type) fail(node, what + ": element '" + name + "' is of type " + e->type() + "; it must be of type " + type);
        return name;
      }
    fail(node, what + ": no element named '" + name + "' in the model (it must be a " + type + ")");
    std::abort();  // not reached (fail throws); GCC's sanitizer build cannot see it through the virtual call
  }

  std::vector<YAML::Node> list(const YAML::Node& node, const std::string& what) const {
    if (!node.IsSequence() || node.size() == 0) fail(node, what + " must be a non-empty list");
    return std::vector<YAML::Node>(node.begin(), node.end());
  }

 private:
  const Model& model_;
  const SectionFail& fail_;
};

int column_of(const DaeSystem& system, const std::string& name) {
  const auto& names = system.output_names();
  const auto it = std::find(names.begin(), names.end(), name);
  RAILCRASH_DEMAND(it != names.end());
  return static_cast<int>(it - names.begin());
}

double distance(const double* y, int a, int b) {
  return std::hypot(y[3 * a] - y[3 * b], y[3 * a + 1] - y[3 * b + 1]);
}

}  // namespace

std::shared_ptr<const ScenarioCriteria> read_scenario_section(const YAML::Node& section, const Model& model, double length_scale,
                                                              const SectionFail& fail) {
  const SectionReader r(model, fail);
  r.check_map_keys(section, {"standard", "number", "category", "closing_speed", "mean_deceleration", "survival_space", "override"},
              "the section");
  auto c = std::make_shared<ScenarioCriteria>();
  c->standard = r.text(r.required(section, "standard", "the section"), "standard");
  const YAML::Node number = r.required(section, "number", "the section");
  c->number = static_cast<int>(r.positive(number, "number"));
  c->category = r.text(r.required(section, "category", "the section"), "category");
  if (c->category != "C-I" && c->category != "C-II" && c->category != "C-III" && c->category != "C-IV")
    r.fail(section["category"], "category must be C-I, C-II, C-III or C-IV (EN 15227's crashworthiness design categories)");
  c->closing_speed = r.positive(r.required(section, "closing_speed", "the section"), "closing_speed");

  const YAML::Node deceleration = r.required(section, "mean_deceleration", "the section");
  r.check_map_keys(deceleration, {"limit", "cfc", "source", "bodies"}, "mean_deceleration");
  c->deceleration_limit = r.positive(r.required(deceleration, "limit", "mean_deceleration"), "mean_deceleration: limit");
  if (deceleration["cfc"]) c->cfc = r.positive(deceleration["cfc"], "mean_deceleration: cfc");
  c->deceleration_source = r.text(r.required(deceleration, "source", "mean_deceleration"), "mean_deceleration: source");
  for (const YAML::Node& b : r.list(r.required(deceleration, "bodies", "mean_deceleration"), "mean_deceleration: bodies"))
    c->passenger_bodies.push_back(r.body(b, "mean_deceleration: bodies"));

  const YAML::Node survival = r.required(section, "survival_space", "the section");
  r.check_map_keys(survival, {"limit", "source", "cars", "excluded", "zones", "gauges"}, "survival_space");
  c->survival_limit = r.positive(r.required(survival, "limit", "survival_space"), "survival_space: limit");
  c->survival_source = r.text(r.required(survival, "source", "survival_space"), "survival_space: source");
  if (!survival["cars"] && !survival["gauges"])
    r.fail(survival, "survival_space: give 'cars: [..]' (the crush of each car's crush elements) and/or 'gauges: [..]' (body pairs)");
  if (survival["cars"])
    for (const YAML::Node& car : r.list(survival["cars"], "survival_space: cars")) {
      const std::string name = r.text(car, "survival_space: cars");
      const auto& bodies = model.bodies();
      if (std::none_of(bodies.begin(), bodies.end(), [&](const Body& b) { return b.car == name; }))
        r.fail(car, "survival_space: cars: no body declares 'car: " + name + "' in the model");
      c->survival_cars.push_back(name);
    }
  if (survival["excluded"])
    for (const YAML::Node& e : r.list(survival["excluded"], "survival_space: excluded")) {
      const std::string name = r.text(e, "survival_space: excluded");
      const auto& elements = model.elements();
      if (std::none_of(elements.begin(), elements.end(), [&](const auto& element) { return element->name() == name; }))
        r.fail(e, "survival_space: excluded: no element named '" + name + "' in the model");
      c->survival_excluded.push_back(name);
    }
  if (survival["zones"])
    for (const YAML::Node& z : r.list(survival["zones"], "survival_space: zones")) {
      r.check_map_keys(z, {"element", "stroke"}, "survival_space: zone");
      const YAML::Node element = r.required(z, "element", "survival_space: zone");
      const std::string name = r.text(element, "survival_space: zone element");
      const auto& elements = model.elements();
      if (std::none_of(elements.begin(), elements.end(), [&](const auto& e) { return e->name() == name; }))
        r.fail(element, "survival_space: zones: no element named '" + name + "' in the model");
      c->survival_zones.push_back({name, r.positive(r.required(z, "stroke", "survival_space: zone " + name),
                                                    "survival_space: zone " + name + ": stroke")});
    }
  if (survival["gauges"])
  for (const YAML::Node& g : r.list(survival["gauges"], "survival_space: gauges")) {
    r.check_map_keys(g, {"name", "front", "rear"}, "survival_space: gauge");
    ScenarioCriteria::Gauge gauge;
    gauge.name = r.text(r.required(g, "name", "survival_space: gauge"), "survival_space: gauge name");
    gauge.front_body = r.body(r.required(g, "front", "survival_space: gauge " + gauge.name), "survival_space: gauge front");
    gauge.rear_body = r.body(r.required(g, "rear", "survival_space: gauge " + gauge.name), "survival_space: gauge rear");
    if (gauge.front_body == gauge.rear_body) r.fail(g, "survival_space: gauge " + gauge.name + ": front and rear must be two bodies");
    c->survival_gauges.push_back(gauge);
  }

  const YAML::Node override_node = r.required(section, "override", "the section");
  r.check_map_keys(override_node, {"limit", "source", "interface", "bodies", "wheel_lift_limit", "wheel_lift_source", "wheels", "rail_supports"},
              "override");
  if (override_node["interface"] && override_node["bodies"])
    r.fail(override_node, "override: give either 'interface: <anticlimber element>' or 'bodies: [A, B]' (the two bodies meeting at the interface), not both");
  if (!override_node["interface"] && !override_node["bodies"] && c->number != 3)
    r.fail(override_node, "override: give 'interface: <anticlimber element>' or 'bodies: [A, B]' (the two bodies meeting at the interface); "
                          "only scenario 3 (an obstacle) has no interface");
  if (override_node["interface"]) {
    c->interface_element = r.element(override_node["interface"], "override: interface", kAnticlimberType);
  } else if (override_node["bodies"]) {
    const auto bodies = r.list(override_node["bodies"], "override: bodies");
    if (bodies.size() != 2) r.fail(override_node["bodies"], "override: bodies must name two bodies [A, B]");
    for (const YAML::Node& b : bodies) c->interface_bodies.push_back(r.body(b, "override: bodies"));
  }
  if (c->has_interface()) {
    c->override_limit = r.positive(r.required(override_node, "limit", "override"), "override: limit");
    c->override_source = r.text(r.required(override_node, "source", "override"), "override: source");
  } else if (override_node["limit"] || override_node["source"]) {
    r.fail(override_node, "override: 'limit' and 'source' belong to an interface ('interface' or 'bodies'), which this scenario has not");
  }
  if (!override_node["wheels"] && !override_node["rail_supports"])
    r.fail(override_node, "override: give 'wheels: [..]' (the leading bogies' wheel_rail elements) or 'rail_supports: [..]' "
                          "(the slider_joints holding them on the rail)");
  if (override_node["rail_supports"])
    for (const YAML::Node& w : r.list(override_node["rail_supports"], "override: rail_supports"))
      c->rail_supports.push_back(r.element(w, "override: rail_supports", "slider_joint"));
  if (override_node["wheels"]) {
    c->wheel_lift_limit = r.positive(r.required(override_node, "wheel_lift_limit", "override"), "override: wheel_lift_limit");
    c->wheel_lift_source = r.text(r.required(override_node, "wheel_lift_source", "override"), "override: wheel_lift_source");
    for (const YAML::Node& w : r.list(override_node["wheels"], "override: wheels"))
      c->wheels.push_back(r.element(w, "override: wheels", "wheel_rail"));
  } else if (override_node["wheel_lift_limit"] || override_node["wheel_lift_source"]) {
    r.fail(override_node, "override: 'wheel_lift_limit' and 'wheel_lift_source' belong to 'wheels' (wheel_rail elements), which this scenario has not");
  }
  if (length_scale != 1.0) {  // its limits are lengths, speeds and decelerations
    for (double* value : {&c->closing_speed, &c->deceleration_limit, &c->survival_limit, &c->override_limit, &c->wheel_lift_limit})
      *value *= length_scale;
    for (ScenarioCriteria::Zone& zone : c->survival_zones) zone.stroke *= length_scale;
  }
  return c;
}

namespace {
[[maybe_unused]] const bool kScenarioSectionReaderRegistered = set_scenario_section_reader(&read_scenario_section);
}  // namespace

double filtered_mean_deceleration(const std::vector<double>& times, const std::vector<double>& vx, double cfc, bool* complete) {
  const double interval = cfc::typical_interval(times);
  std::vector<double> t = times, v = vx;
  if (times.size() >= 3 && interval > 0.0 && cfc::design_frequency(cfc) * interval < 0.5) {
    v = cfc::filter(cfc::resample_uniform(times, vx, interval), interval, cfc);
    t.resize(v.size());
    for (std::size_t k = 0; k < t.size(); ++k) t[k] = times.front() + static_cast<double>(k) * interval;
  }
  const CollisionPulse pulse = collision_pulse(t, v);
  if (complete) *complete = pulse.complete;
  return pulse.mean_deceleration;
}

double largest_shortening(const std::vector<double>& lengths) {
  double largest = 0.0;
  for (const double length : lengths) largest = std::max(largest, lengths.front() - length);
  return largest;
}

double largest_change(const std::vector<double>& values) {
  double largest = 0.0;
  for (const double value : values) largest = std::max(largest, std::abs(value - values.front()));
  return largest;
}


double largest_lift(const std::vector<double>& penetration) {
  double largest = 0.0;
  for (const double p : penetration) largest = std::max(largest, -p);
  return largest;
}

double static_load(const std::vector<double>& reaction) {
  for (const double q : reaction)
    if (q != 0.0) return q;
  return 0.0;
}

double largest_unloading(const std::vector<double>& reaction) { return largest_unloading(reaction, static_load(reaction)); }

double largest_unloading(const std::vector<double>& reaction, double q0) {
  if (q0 == 0.0) return reaction.empty() ? 0.0 : std::numeric_limits<double>::infinity();
  double lowest = 1.0;  // Q / Q0, from the first known reaction on
  const auto first = std::find_if(reaction.begin(), reaction.end(), [](double q) { return q != 0.0; });
  for (auto q = first; q != reaction.end(); ++q) lowest = std::min(lowest, *q / q0);
  return 1.0 - lowest;
}

ScenarioTracker::ScenarioTracker(const DaeSystem& system, const ScenarioCriteria& criteria)
    : system_(system), criteria_(criteria) {
  const Model& model = system.model();
  for (const std::string& b : criteria.passenger_bodies) passenger_index_.push_back(*model.find_body(b));
  for (const auto& g : criteria.survival_gauges) {
    front_index_.push_back(*model.find_body(g.front_body));
    rear_index_.push_back(*model.find_body(g.rear_body));
  }
  for (const std::string& name : criteria.survival_cars) {
    const std::vector<CarCrush> cars = cars_of(system);
    const auto car = std::find_if(cars.begin(), cars.end(), [&](const CarCrush& c) { return c.car == name; });
    RAILCRASH_DEMAND(car != cars.end());  // the section reader checked that a body declares the car
    CarCrush kept = *car;  // without the excluded elements
    kept.elements.clear();
    kept.element_indices.clear();
    kept.columns.clear();
    kept.shares.clear();
    std::vector<double> allowed;  // [length] 0, or a declared zone's stroke
    for (std::size_t k = 0; k < car->elements.size(); ++k) {
      const auto& excluded = criteria.survival_excluded;
      if (std::find(excluded.begin(), excluded.end(), car->elements[k]) != excluded.end()) continue;
      kept.elements.push_back(car->elements[k]);
      kept.element_indices.push_back(car->element_indices[k]);
      kept.columns.push_back(car->columns[k]);
      kept.shares.push_back(car->shares[k]);
      const auto& zones = criteria.survival_zones;
      const auto zone = std::find_if(zones.begin(), zones.end(), [&](const auto& z) { return z.element == car->elements[k]; });
      allowed.push_back(zone == zones.end() ? 0.0 : zone->stroke);
    }
    crush_of_cars_.push_back(kept);
    allowed_.push_back(allowed);
  }
  if (!criteria.interface_element.empty()) {
    vertical_offset_column_ = column_of(system, criteria.interface_element + ".vertical_offset");
    override_column_ = column_of(system, criteria.interface_element + ".override");
  } else if (!criteria.interface_bodies.empty()) {
    interface_lower_ = *model.find_body(criteria.interface_bodies[0]);
    interface_upper_ = *model.find_body(criteria.interface_bodies[1]);
  }
  for (const std::string& w : criteria.wheels) wheel_columns_.push_back(column_of(system, w + ".penetration"));
  for (const std::string& w : criteria.rail_supports) support_columns_.push_back(column_of(system, w + ".normal_reaction"));
  reaction_.resize(support_columns_.size());
  step_extremes_.lowest_load.assign(support_columns_.size(), 1.0);
  vx_.resize(passenger_index_.size());
  lengths_.resize(front_index_.size());
  car_crush_.resize(crush_of_cars_.size());
  penetration_.resize(wheel_columns_.size());
  step_extremes_.shortening.assign(front_index_.size(), 0.0);
  step_extremes_.car_crush.assign(crush_of_cars_.size(), 0.0);
  step_extremes_.lift.assign(wheel_columns_.size(), 0.0);
}

double ScenarioTracker::car_crush_now(std::size_t k, const double* outputs) const {
  return shared_crush(outputs, crush_of_cars_[k].columns, crush_of_cars_[k].shares, &allowed_[k]);
}

void ScenarioTracker::mark_step_columns(std::vector<char>& columns) const {
  const auto mark = [&](int column) {
    if (column >= 0) columns[static_cast<std::size_t>(column)] = 1;
  };
  for (const CarCrush& car : crush_of_cars_)
    for (const int column : car.columns) mark(column);
  mark(vertical_offset_column_);
  mark(override_column_);
  for (const int column : wheel_columns_) mark(column);
  for (const int column : support_columns_) mark(column);
}

void ScenarioTracker::step(double, const double* y, const double* lambda, const double* outputs, const FreshOutputs& fresh) {
  if (times_.empty()) return;  // the references (L(0), the offset at 0) come from the first sample
  for (std::size_t k = 0; k < front_index_.size(); ++k)
    step_extremes_.shortening[k] =
        std::max(step_extremes_.shortening[k], lengths_[k].front() - distance(y, front_index_[k], rear_index_[k]));
  // A car's crush sums several elements' outputs, all of one instant (car_elements_crush_at).
  for (std::size_t k = 0; k < crush_of_cars_.size(); ++k) {
    const std::optional<double> crush = car_elements_crush_at(system_, crush_of_cars_[k], y, lambda, outputs, fresh, crush_scratch_, &allowed_[k]);
    if (crush) step_extremes_.car_crush[k] = std::max(step_extremes_.car_crush[k], *crush);
  }
  bool offset_known = true;
  double offset = 0.0;  // [length]
  if (vertical_offset_column_ >= 0) {
    offset_known = fresh.has(vertical_offset_column_);
    offset = outputs[vertical_offset_column_];
    if (fresh.has(override_column_)) overridden_ = overridden_ || outputs[override_column_] > 0.0;
  } else if (interface_upper_ >= 0) {
    offset = y[3 * interface_upper_ + 1] - y[3 * interface_lower_ + 1];
  }
  if (!vertical_offset_.empty() && offset_known)
    step_extremes_.offset_change = std::max(step_extremes_.offset_change, std::abs(offset - vertical_offset_.front()));
  for (std::size_t k = 0; k < wheel_columns_.size(); ++k)
    if (fresh.has(wheel_columns_[k])) step_extremes_.lift[k] = std::max(step_extremes_.lift[k], -outputs[wheel_columns_[k]]);
  for (std::size_t k = 0; k < support_columns_.size(); ++k)
    if (const double q0 = wheel_static_load(k); fresh.has(support_columns_[k]) && q0 != 0.0 && static_load(reaction_[k]) != 0.0)
      step_extremes_.lowest_load[k] = std::min(step_extremes_.lowest_load[k], outputs[support_columns_[k]] / q0);
}

void ScenarioTracker::sample(double t, const double* y, const double*, const double*, const double* outputs) {
  times_.push_back(t);
  const double* velocities = y + system_.body_unknowns();
  for (std::size_t k = 0; k < passenger_index_.size(); ++k) vx_[k].push_back(velocities[3 * passenger_index_[k]]);
  for (std::size_t k = 0; k < front_index_.size(); ++k) lengths_[k].push_back(distance(y, front_index_[k], rear_index_[k]));
  for (std::size_t k = 0; k < crush_of_cars_.size(); ++k) car_crush_[k].push_back(car_crush_now(k, outputs));
  if (vertical_offset_column_ >= 0) {
    vertical_offset_.push_back(outputs[vertical_offset_column_]);
    overridden_ = overridden_ || outputs[override_column_] > 0.0;
  } else if (interface_upper_ >= 0) {
    vertical_offset_.push_back(y[3 * interface_upper_ + 1] - y[3 * interface_lower_ + 1]);
  }
  for (std::size_t k = 0; k < wheel_columns_.size(); ++k)
    penetration_[k].push_back(outputs[wheel_columns_[k]]);
  for (std::size_t k = 0; k < support_columns_.size(); ++k) reaction_[k].push_back(outputs[support_columns_[k]]);
  if (times_.size() == 1) static_load_ = static_loads(t, y);
}

double ScenarioTracker::wheel_static_load(std::size_t k) const {
  return k < static_load_.size() ? static_load_[k] : static_load(reaction_[k]);
}

std::vector<double> ScenarioTracker::static_loads(double t, const double* y) const {
  // The rates and multipliers consistent with the sample's positions and velocities, as IDA
  // starts from them (consistent_rates); the supports' reactions there.
  std::vector<double> consistent(y, y + system_.size()), rates;
  try {
    consistent_rates(system_, t, consistent, rates);
  } catch (const SolverError&) {
    // No consistent multipliers (a zero-inertia body no joint holds: IDA could not start
    // either): Q0 is the first non-zero sample, as before.
    return {};
  }
  std::vector<double> outputs(system_.output_names().size(), 0.0);
  system_.outputs(consistent.data(), consistent.data() + 2 * system_.body_unknowns(), outputs.data());
  std::vector<double> loads;
  for (const int column : support_columns_) loads.push_back(outputs[static_cast<std::size_t>(column)]);
  return loads;
}

std::vector<CriterionResult> ScenarioTracker::results() const {
  std::vector<CriterionResult> out;
  if (times_.empty()) return out;
  for (std::size_t k = 0; k < passenger_index_.size(); ++k) {
    CriterionResult r;
    r.criterion = "mean_deceleration";
    r.subject = criteria_.passenger_bodies[k];
    bool complete = false;
    r.value = filtered_mean_deceleration(times_, vx_[k], criteria_.cfc, &complete);
    r.limit = criteria_.deceleration_limit;
    r.pass = r.value <= r.limit;
    if (!complete) r.note = "the velocity change had not ended at the end of the run";
    out.push_back(r);
  }
  for (std::size_t k = 0; k < crush_of_cars_.size(); ++k) {
    CriterionResult r;
    r.criterion = "survival_space";
    r.subject = criteria_.survival_cars[k];
    r.value = std::max(*std::max_element(car_crush_[k].begin(), car_crush_[k].end()), step_extremes_.car_crush[k]);
    r.limit = criteria_.survival_limit;
    r.pass = r.value <= r.limit;
    if (crush_of_cars_[k].columns.empty()) {  // nothing measured: not a pass
      r.pass = false;
      r.note = "not measured: the car has no crush element (no output with the crush role) besides the excluded ones";
    } else if (std::any_of(allowed_[k].begin(), allowed_[k].end(), [](double stroke) { return stroke > 0.0; })) {
      r.note = r.value > 0.0 ? "crushed beyond its declared crush zones' strokes or in crush elements not declared zones"
                             : "its crush stayed within its declared crush zones";
    }
    out.push_back(r);
  }
  for (std::size_t k = 0; k < front_index_.size(); ++k) {
    CriterionResult r;
    r.criterion = "survival_gauge";
    r.subject = criteria_.survival_gauges[k].name;
    r.value = std::max(largest_shortening(lengths_[k]), step_extremes_.shortening[k]);
    r.limit = criteria_.survival_limit;
    r.pass = r.value <= r.limit;
    out.push_back(r);
  }
  if (criteria_.has_interface()) out.push_back(interface_result());
  for (std::size_t k = 0; k < wheel_columns_.size(); ++k) {
    CriterionResult r;
    r.criterion = "wheel_lift";
    r.subject = criteria_.wheels[k];
    r.value = std::max(largest_lift(penetration_[k]), step_extremes_.lift[k]);
    r.limit = criteria_.wheel_lift_limit;
    r.pass = r.value <= r.limit;
    out.push_back(r);
  }
  for (std::size_t k = 0; k < support_columns_.size(); ++k) {
    CriterionResult r;
    r.criterion = "wheel_unloading";
    r.subject = criteria_.rail_supports[k];
    r.value = std::max(largest_unloading(reaction_[k], wheel_static_load(k)), 1.0 - step_extremes_.lowest_load[k]);
    r.limit = 1.0;
    r.pass = r.value < r.limit;
    r.note = !std::isfinite(r.value) ? "no static wheel load at the start (no gravity?): unloading not measured"
             : r.pass                ? "the rail kept bearing the bogie"
                                     : "the rail reaction reversed: the bogie's wheels would lift";
    out.push_back(r);
  }
  return out;
}

CriterionResult ScenarioTracker::interface_result() const {
  CriterionResult interface;
  interface.criterion = "override";
  interface.subject = criteria_.interface_element.empty() ? criteria_.interface_bodies[0] + " / " + criteria_.interface_bodies[1]
                                                          : criteria_.interface_element;
  interface.value = std::max(largest_change(vertical_offset_), step_extremes_.offset_change);
  interface.limit = criteria_.override_limit;
  interface.pass = interface.value <= interface.limit && !overridden_;
  if (overridden_) interface.note = "the anticlimber faces overrode each other";
  return interface;
}

std::string ScenarioTracker::json() const {
  const std::vector<CriterionResult> all = results();
  const double g = standard_gravity(system_.model());
  std::ostringstream j;
  bool pass = !all.empty();
  for (const auto& r : all) pass = pass && r.pass;
  j << "{\"standard\": " << json_string(criteria_.standard) << ", \"number\": " << criteria_.number
    << ", \"category\": " << json_string(criteria_.category) << ", \"closing_speed\": " << json_number(criteria_.closing_speed)
    << ", \"pass\": " << (pass ? "true" : "false") << ", \"sources\": {\"mean_deceleration\": " << json_string(criteria_.deceleration_source)
    << ", \"survival_space\": " << json_string(criteria_.survival_source) << ", \"override\": " << json_string(criteria_.override_source)
    << ", \"wheel_lift\": " << json_string(criteria_.wheel_lift_source);
  if (!criteria_.rail_supports.empty())
    j << ", \"wheel_unloading\": \"limit 1: at (Q0 - Q) / Q0 = 1 the rail would pull the bogie down (a physical bound)\"";
  j << "}, \"criteria\": [";
  for (std::size_t k = 0; k < all.size(); ++k) {
    const CriterionResult& r = all[k];
    j << (k ? ", " : "") << "{\"criterion\": " << json_string(r.criterion) << ", \"subject\": " << json_string(r.subject)
      << ", \"value\": " << json_number(r.value) << ", \"limit\": " << json_number(r.limit) << ", \"margin\": " << json_number(r.margin());
    if (r.criterion == "mean_deceleration")
      j << ", \"value_g\": " << json_number(r.value / g) << ", \"limit_g\": " << json_number(r.limit / g);
    j << ", \"pass\": " << (r.pass ? "true" : "false") << ", \"note\": " << json_string(r.note) << "}";
  }
  j << "]}";
  return j.str();
}

}  // namespace railcrash
