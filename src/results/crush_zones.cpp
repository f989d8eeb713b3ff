// Energy absorbed per crush zone and per car (see the header).
#include "railcrash/results/crush_zones.hpp"

#include <algorithm>
#include <sstream>

#include "railcrash/elements/anticlimber.hpp"
#include "railcrash/elements/couplers.hpp"
#include "railcrash/elements/crush.hpp"
#include "railcrash/model/element.hpp"
#include "railcrash/results/results.hpp"

namespace railcrash {

double area_under(const DeclaredCurve& curve) {
  double area = 0.0;  // [force*length] trapezoids
  for (std::size_t k = 1; k < curve.deformation.size(); ++k)
    area += 0.5 * (curve.force[k] + curve.force[k - 1]) * (curve.deformation[k] - curve.deformation[k - 1]);
  return area;
}

std::optional<DeclaredCurve> declared_curve(const Element& element) {
  DeclaredCurve curve;
  if (const auto* spring = dynamic_cast<const CrushSpring*>(&element)) {
    curve.deformation = spring->curve_crush;
    curve.force = spring->curve_force;
    curve.unloading_stiffness = spring->unloading_stiffness;
    return curve;
  }
  if (const Anticlimber* anticlimber = as_anticlimber(element)) {
    const ElasticPlasticLaw& h = anticlimber->horizontal;
    const double yield = h.rupture_deflection ? std::min(h.yield_deflection, *h.rupture_deflection) : h.yield_deflection;
    curve.deformation = {0.0, yield};
    curve.force = {0.0, h.elastic_stiffness * yield};
    if (!h.rupture_deflection) {  // no last point: the curve goes on at the plastic slope
      curve.open_ended = true;
      curve.beyond_last_slope = h.plastic_stiffness;
    }
    else if (*h.rupture_deflection > yield) {
      curve.deformation.push_back(*h.rupture_deflection);
      curve.force.push_back(h.yield_force() + h.plastic_stiffness * (*h.rupture_deflection - h.yield_deflection));
    }
    curve.unloading_stiffness = h.elastic_stiffness;
    return curve;
  }
  if (const auto* gear = dynamic_cast<const DraftGear*>(&element)) {
    const double k = gear->initial_stiffness, h = gear->hysteresis_load, travel = gear->travel;
    curve.deformation = {0.0, travel};
    curve.force = {h, k * travel + h};
    curve.unloading_stiffness = gear->transition_stiffness;
    curve.beyond_last_slope = gear->stiffness_after_bottoming;  // bottomed
    if (k * travel > h) {  // the unloading curve k d - H, from where it reaches zero force
      curve.lower_deformation = {h / k, travel};
      curve.lower_force = {0.0, k * travel - h};
    }
    return curve;
  }
  return std::nullopt;
}

CrushZoneTracker::CrushZoneTracker(const DaeSystem& system) : system_(system) {
  const Model& model = system.model();
  const auto& elements = model.elements();
  for (std::size_t e = 0; e < elements.size(); ++e) {
    const Element& element = *elements[e];
    const bool crushes = !element.output_with_role(OutputRole::Crush).empty() ||
                         (!element.output_with_role(OutputRole::CrashForce).empty() &&
                          !element.output_with_role(OutputRole::CrashDeformation).empty());
    if (!crushes) continue;
    CrushZone zone;
    zone.element = element.name();
    zone.type = element.type();
    zone.element_index = static_cast<int>(e);
    for (int slot = 0; slot < 2; ++slot) {
      const int body = element.slot_body(slot);
      if (body == kGround) continue;
      const std::string& car = model.bodies()[static_cast<std::size_t>(body)].car;
      if (car.empty() || std::find(zone.cars.begin(), zone.cars.end(), car) != zone.cars.end()) continue;
      zone.cars.push_back(car);
    }
    zone.shares.assign(zone.cars.size(), zone.cars.empty() ? 0.0 : 1.0 / static_cast<double>(zone.cars.size()));
    zone.curve = declared_curve(element);
    if (zone.curve && !zone.curve->open_ended) zone.capacity = area_under(*zone.curve);
    zones_.push_back(zone);
  }
  for (const Body& body : model.bodies())  // cars in the order of their first body
    if (!body.car.empty() && std::find(car_order_.begin(), car_order_.end(), body.car) == car_order_.end())
      car_order_.push_back(body.car);
}

void CrushZoneTracker::sample(const double* y, const double* quadratures) {
  for (CrushZone& zone : zones_) {
    const double stored = system_.element_potential_energy(static_cast<std::size_t>(zone.element_index), y);
    if (first_) zone.initial_recoverable = stored;
    zone.recoverable = stored;
    zone.absorbed = quadratures ? quadratures[DaeSystem::kFirstElementWork + zone.element_index] : 0.0;
    zone.peak_absorbed = first_ ? zone.absorbed : std::max(zone.peak_absorbed, zone.absorbed);
    zone.dissipated = zone.absorbed - (zone.recoverable - zone.initial_recoverable);
  }
  first_ = false;
}

std::vector<CarEnergy> CrushZoneTracker::cars() const {
  std::vector<CarEnergy> cars;
  for (const std::string& name : car_order_) cars.push_back(CarEnergy{name, 0.0, 0.0});
  for (const CrushZone& zone : zones_)
    for (std::size_t k = 0; k < zone.cars.size(); ++k) {
      auto car = std::find_if(cars.begin(), cars.end(), [&](const CarEnergy& c) { return c.car == zone.cars[k]; });
      car->absorbed += zone.shares[k] * zone.absorbed;
      car->capacity += zone.shares[k] * zone.capacity.value_or(0.0);
    }
  return cars;
}

double CrushZoneTracker::total_absorbed() const {
  double total = 0.0;
  for (const CrushZone& zone : zones_) total += zone.absorbed;
  return total;
}

namespace {

std::string numbers_json(const std::vector<double>& values) {
  std::string out = "[";
  for (std::size_t k = 0; k < values.size(); ++k) out += (k ? ", " : "") + json_number(values[k]);
  return out + "]";
}

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

}  // namespace

std::string CrushZoneTracker::json(bool si) const {
  const double total = total_absorbed();
  const auto share_of_total = [&](double value) { return total > 0.0 ? json_number(value / total) : std::string("null"); };
  std::ostringstream j;
  j << "{\"note\": " << json_string(std::string("absorbed: work done on the element (") + (si ? "J" : "in*lbf") +
                                    "), dissipated + the change of its recoverable (elastic) energy; capacity: area under "
                                    "its declared loading curve up to the curve's last point; share: of total_absorbed")
    << ", \"total_absorbed\": " << json_number(total) << ", \"zones\": [";
  for (std::size_t z = 0; z < zones_.size(); ++z) {
    const CrushZone& zone = zones_[z];
    j << (z ? ", " : "") << "{\"element\": " << json_string(zone.element) << ", \"type\": " << json_string(zone.type)
      << ", \"cars\": [";
    for (std::size_t k = 0; k < zone.cars.size(); ++k)
      j << (k ? ", " : "") << "{\"car\": " << json_string(zone.cars[k]) << ", \"share\": " << json_number(zone.shares[k]) << "}";
    j << "], \"absorbed\": " << json_number(zone.absorbed) << ", \"peak_absorbed\": " << json_number(zone.peak_absorbed)
      << ", \"dissipated\": " << json_number(zone.dissipated) << ", \"recoverable\": " << json_number(zone.recoverable)
      << ", \"share_of_total\": " << share_of_total(zone.absorbed)
      << ", \"capacity\": " << (zone.capacity ? json_number(*zone.capacity) : std::string("null"))
      << ", \"capacity_used\": " << (zone.capacity && *zone.capacity > 0.0 ? json_number(zone.absorbed / *zone.capacity) : std::string("null"));
    if (zone.curve) {
      const DeclaredCurve& c = *zone.curve;
      j << ", \"curve\": {\"deformation\": " << numbers_json(c.deformation) << ", \"force\": " << numbers_json(c.force)
        << ", \"unloading_stiffness\": " << json_number(c.unloading_stiffness);
      if (c.beyond_last_slope) j << ", \"beyond_last_slope\": " << json_number(*c.beyond_last_slope);
      j << ", \"open_ended\": " << (c.open_ended ? "true" : "false");
      if (!c.lower_deformation.empty())
        j << ", \"lower_deformation\": " << numbers_json(c.lower_deformation) << ", \"lower_force\": " << numbers_json(c.lower_force);
      j << "}";
    }
    j << "}";
  }
  j << "], \"cars\": {";
  const std::vector<CarEnergy> per_car = cars();
  for (std::size_t c = 0; c < per_car.size(); ++c)
    j << (c ? ", " : "") << json_string(per_car[c].car) << ": {\"absorbed\": " << json_number(per_car[c].absorbed)
      << ", \"capacity\": " << json_number(per_car[c].capacity) << ", \"share_of_total\": " << share_of_total(per_car[c].absorbed) << "}";
  j << "}}";
  return j.str();
}

std::string CrushZoneTracker::csv() const {
  const double total = total_absorbed();
  std::ostringstream out;
  out << "kind,name,type,cars,absorbed,peak_absorbed,dissipated,recoverable,capacity,share_of_total\n";
  const auto share = [&](double value) { return total > 0.0 ? json_number(value / total) : std::string(); };
  for (const CrushZone& zone : zones_) {
    std::string cars;
    for (std::size_t k = 0; k < zone.cars.size(); ++k) cars += (k ? " " : "") + zone.cars[k];
    out << "zone," << csv_field(zone.element) << "," << zone.type << "," << csv_field(cars) << "," << json_number(zone.absorbed) << ","
        << json_number(zone.peak_absorbed) << "," << json_number(zone.dissipated) << "," << json_number(zone.recoverable) << ","
        << (zone.capacity ? json_number(*zone.capacity) : std::string()) << "," << share(zone.absorbed) << "\n";
  }
  for (const CarEnergy& car : cars())
    out << "car," << csv_field(car.car) << ",,," << json_number(car.absorbed) << ",,,," << json_number(car.capacity) << ","
        << share(car.absorbed) << "\n";
  out << "total,all crush zones,,," << json_number(total) << ",,,,,1\n";
  return out.str();
}

}  // namespace railcrash
