#include "railcrash/results.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

namespace railcrash {

void body_accelerations(const DaeSystem& system, double t, const double* y, const double* lambda, double* acceleration) {
  const int nq = system.body_unknowns();
  const int m = system.constraint_rows();
  system.generalized_forces(t, y, y + nq, acceleration, nullptr, nullptr, lambda);
  if (m > 0 && lambda != nullptr) {
    std::vector<double> phi(static_cast<std::size_t>(m));
    std::vector<DaeSystem::Triplet> gradient;
    system.constraints(y, phi.data(), &gradient);
    for (const DaeSystem::Triplet& g : gradient) acceleration[g.col] -= g.value * lambda[g.row];
  }
  for (int k = 0; k < nq; ++k) acceleration[k] /= system.mass_diagonal(k);
}

double standard_gravity(const Model& model) { return model.units == UnitSystem::SI ? 9.80665 : 386.088; }

std::vector<CarCrush> cars_of(const DaeSystem& system) {
  const Model& model = system.model();
  const std::regex prefix("^(car[0-9]+)_.*");
  std::vector<std::string> car_of_body;
  std::vector<CarCrush> cars;
  bool named = false;
  for (const Body& b : model.bodies()) {
    std::smatch match;
    const bool is_car = std::regex_match(b.name, match, prefix);
    named = named || is_car;
    car_of_body.push_back(is_car ? match[1].str() : std::string());
  }
  for (std::string& c : car_of_body)
    if (!named) c = "car";
  for (const std::string& c : car_of_body)
    if (!c.empty() && std::none_of(cars.begin(), cars.end(), [&](const CarCrush& k) { return k.car == c; }))
      cars.push_back(CarCrush{c, {}, {}, {}, 0.0, 0.0});
  const auto& names = system.output_names();
  for (const auto& e : model.elements()) {
    std::string quantity;
    if (e->type() == "anticlimber") quantity = "horizontal_deformation";
    else if (e->type() == "crush_spring") quantity = "crush";
    else continue;
    const auto it = std::find(names.begin(), names.end(), e->name() + "." + quantity);
    if (it == names.end()) continue;
    std::vector<std::string> touched;
    for (int slot = 0; slot < 2; ++slot) {
      const int body = e->slot_body(slot);
      if (body == kGround) continue;
      const std::string& c = car_of_body[static_cast<std::size_t>(body)];
      if (!c.empty() && std::find(touched.begin(), touched.end(), c) == touched.end()) touched.push_back(c);
    }
    for (const std::string& c : touched)
      for (CarCrush& car : cars)
        if (car.car == c) {
          car.elements.push_back(e->name());
          car.columns.push_back(static_cast<int>(it - names.begin()));
          car.shares.push_back(1.0 / static_cast<double>(touched.size()));
        }
  }
  return cars;
}

std::string json_string(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buffer[8];
          std::snprintf(buffer, sizeof buffer, "\\u%04x", c);
          out += buffer;
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

std::string json_number(double value) {
  if (!std::isfinite(value)) return "null";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.12g", value);
  return buffer;
}

std::vector<std::string> timeseries_columns(const DaeSystem& system) {
  std::vector<std::string> names{"t"};
  for (const Body& b : system.model().bodies())
    for (const char* q : {"x", "y", "theta", "vx", "vy", "omega"}) names.push_back(b.name + "." + q);
  for (const std::string& name : system.output_names()) names.push_back(name);
  return names;
}

ResultWriter::ResultWriter(const std::string& directory, const DaeSystem& system, bool keep_in_memory)
    : system_(system), directory_(directory), last_flush_(std::chrono::steady_clock::now()) {
  const std::vector<std::string> names = timeseries_columns(system);
  if (!directory.empty()) {
    std::error_code error;
    std::filesystem::create_directories(directory, error);
    if (error) throw InputError("cannot create the output folder '" + directory + "': " + error.message());
    timeseries_ = std::fopen((directory + "/timeseries.csv").c_str(), "w");
    events_ = std::fopen((directory + "/events.csv").c_str(), "w");
    if (!timeseries_ || !events_) throw InputError("cannot write into the output folder '" + directory + "'");
    for (std::size_t k = 0; k < names.size(); ++k) std::fprintf(timeseries_, "%s%s", k ? "," : "", names[k].c_str());
    std::fputs("\n", timeseries_);
    std::fputs("t,element,event,value\n", events_);
  }
  if (keep_in_memory) columns_.resize(names.size());
  output_values_.assign(system.output_names().size(), 0.0);
  peak_output_.assign(system.output_names().size(), 0.0);
  peak_time_.assign(system.output_names().size(), 0.0);
  acceleration_.assign(static_cast<std::size_t>(system.body_unknowns()), 0.0);
  acceleration_peaks_.assign(static_cast<std::size_t>(system.model().body_count()), AccelerationPeaks{});
  cars_ = cars_of(system);
}

ResultWriter::~ResultWriter() {
  if (timeseries_) std::fclose(timeseries_);
  if (events_) std::fclose(events_);
}

void ResultWriter::sample(double t, const double* y, const double* lambda, const double*) {
  const int n = system_.model().body_count();
  const int nq = 3 * n;
  if (timeseries_) {
    std::fprintf(timeseries_, "%.12g", t);
    for (int i = 0; i < n; ++i)
      std::fprintf(timeseries_, ",%.12g,%.12g,%.12g,%.12g,%.12g,%.12g", y[3 * i], y[3 * i + 1], y[3 * i + 2], y[nq + 3 * i],
                   y[nq + 3 * i + 1], y[nq + 3 * i + 2]);
  }
  system_.outputs(y, lambda, output_values_.data());
  for (std::size_t k = 0; k < output_values_.size(); ++k) {
    if (timeseries_) std::fprintf(timeseries_, ",%.12g", output_values_[k]);
    if (std::abs(output_values_[k]) > peak_output_[k]) {
      peak_output_[k] = std::abs(output_values_[k]);
      peak_time_[k] = t;
    }
  }
  if (timeseries_) std::fputs("\n", timeseries_);
  if (!columns_.empty()) {  // same order as the CSV columns
    std::size_t column = 0;
    columns_[column++].push_back(t);
    for (int i = 0; i < n; ++i)
      for (const int k : {3 * i, 3 * i + 1, 3 * i + 2, nq + 3 * i, nq + 3 * i + 1, nq + 3 * i + 2})
        columns_[column++].push_back(y[k]);
    for (const double value : output_values_) columns_[column++].push_back(value);
  }
  body_accelerations(system_, t, y, lambda, acceleration_.data());
  for (int i = 0; i < n; ++i) {
    AccelerationPeaks& p = acceleration_peaks_[static_cast<std::size_t>(i)];
    const double ax = acceleration_[static_cast<std::size_t>(3 * i)], ay = acceleration_[static_cast<std::size_t>(3 * i + 1)];
    const double magnitude = std::hypot(ax, ay);
    if (std::abs(ax) > p.x) { p.x = std::abs(ax); p.t_x = t; }
    if (std::abs(ay) > p.y) { p.y = std::abs(ay); p.t_y = t; }
    if (magnitude > p.magnitude) { p.magnitude = magnitude; p.t_magnitude = t; }
  }
  for (CarCrush& car : cars_) {
    double crush = 0.0;
    for (std::size_t k = 0; k < car.columns.size(); ++k)
      crush += car.shares[k] * std::max(0.0, output_values_[static_cast<std::size_t>(car.columns[k])]);
    if (crush > car.max_crush) { car.max_crush = crush; car.t = t; }
  }
  // Keep what is on disk current without flushing every row.
  if (!timeseries_) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_flush_ > std::chrono::milliseconds(500)) {
    std::fflush(timeseries_);
    std::fflush(events_);
    last_flush_ = now;
  }
}

void ResultWriter::event(const EventRecord& record, const double*) {
  if (!events_) return;  // in memory, the events are the run outcome's
  std::string element = record.element, what = record.what;
  for (std::string* text : {&element, &what})
    if (text->find_first_of(",\"") != std::string::npos) {
      std::string quoted = "\"";
      for (char c : *text) quoted += (c == '"') ? std::string("\"\"") : std::string(1, c);
      *text = quoted + "\"";
    }
  std::fprintf(events_, "%.12g,%s,%s,%.12g\n", record.t, element.c_str(), what.c_str(), record.value);
}

std::string ResultWriter::write_summary(const RunOutcome& outcome, const std::string& integrator, const std::string& extra_json) {
  if (timeseries_) std::fflush(timeseries_);
  if (events_) std::fflush(events_);
  const Model& model = system_.model();
  const bool si = model.units == UnitSystem::SI;
  const EnergyBalance energy = EnergyBalance::between(outcome.initial_energy, outcome.final_energy);
  const RunStatistics& s = outcome.stats;
  std::ostringstream j;
  j << "{\n";
  j << "  \"status\": " << json_string(outcome.ok ? "ok" : "failed") << ",\n";
  j << "  \"message\": " << json_string(outcome.message) << ",\n";
  j << "  \"model\": " << json_string(model.name) << ",\n";
  j << "  \"t_reached\": " << json_number(outcome.t_reached) << ",\n";
  j << "  \"integrator\": " << json_string(integrator) << ",\n";
  j << "  \"units\": {\"system\": " << json_string(unit_system_name(model.units)) << ", \"length\": "
    << json_string(si ? "m" : "in") << ", \"time\": \"s\", \"force\": " << json_string(si ? "N" : "lbf")
    << ", \"mass\": " << json_string(si ? "kg" : "lbf*s^2/in") << ", \"angle\": \"rad\", \"energy\": "
    << json_string(si ? "J" : "in*lbf") << "},\n";
  j << "  \"stats\": {\"steps\": " << s.steps << ", \"residual_evaluations\": " << s.residual_evaluations
    << ", \"jacobian_evaluations\": " << s.jacobian_evaluations << ", \"nonlinear_iterations\": " << s.nonlinear_iterations
    << ", \"error_test_failures\": " << s.error_test_failures
    << ", \"nonlinear_convergence_failures\": " << s.nonlinear_convergence_failures << ", \"events\": " << s.events
    << ", \"located_mode_changes\": " << s.root_returns << ", \"reinitializations\": " << s.reinitializations << ", \"wall_seconds\": " << json_number(s.wall_seconds)
    << ", \"last_step\": " << json_number(s.last_step) << ", \"stability_limit\": " << json_number(s.stability_limit)
    << ", \"assembly_correction\": " << json_number(s.assembly_correction)
    << ", \"settling_steps\": " << s.settling_steps << ", \"settling_displacement\": " << json_number(s.settling_displacement)
    << ", \"unknowns\": " << system_.size() << ", \"jacobian_nonzeros\": " << system_.pattern().nonzeros() << "},\n";
  j << "  \"constraint_residual_max\": " << json_number(outcome.max_constraint_residual) << ",\n";
  const double scale = std::max({std::abs(energy.initial_total), std::abs(energy.kinetic) + std::abs(energy.elastic) +
                                                                     std::abs(energy.gravity) + std::abs(energy.dissipated) +
                                                                     std::abs(energy.external_work)});
  j << "  \"energy\": {\"kinetic\": " << json_number(energy.kinetic) << ", \"elastic\": " << json_number(energy.elastic)
    << ", \"gravity\": " << json_number(energy.gravity) << ", \"dissipated\": " << json_number(energy.dissipated)
    << ", \"external_work\": " << json_number(energy.external_work) << ", \"initial_total\": "
    << json_number(energy.initial_total) << ", \"balance_error\": " << json_number(energy.error())
    << ", \"relative_balance_error\": " << json_number(scale > 0.0 ? energy.error() / scale : 0.0) << "},\n";
  const double ke_integral = outcome.quadratures.empty() ? 0.0 : outcome.quadratures[DaeSystem::kKineticIntegral];
  j << "  \"kinetic_energy_integral\": " << json_number(ke_integral) << ",\n";
  j << "  \"peaks\": {";
  for (std::size_t k = 0; k < peak_output_.size(); ++k)
    j << (k ? ", " : "") << json_string(system_.output_names()[k]) << ": {\"abs_max\": " << json_number(peak_output_[k])
      << ", \"t\": " << json_number(peak_time_[k]) << "}";
  j << "},\n";
  const double g = standard_gravity(model);
  j << "  \"peak_accelerations\": {\"standard_gravity\": " << json_number(g) << ", \"bodies\": {";
  for (std::size_t i = 0; i < acceleration_peaks_.size(); ++i) {
    const AccelerationPeaks& p = acceleration_peaks_[i];
    j << (i ? ", " : "") << json_string(model.bodies()[i].name) << ": {\"x\": {\"abs_max\": " << json_number(p.x)
      << ", \"g\": " << json_number(p.x / g) << ", \"t\": " << json_number(p.t_x) << "}, \"y\": {\"abs_max\": "
      << json_number(p.y) << ", \"g\": " << json_number(p.y / g) << ", \"t\": " << json_number(p.t_y)
      << "}, \"magnitude\": {\"max\": " << json_number(p.magnitude) << ", \"g\": " << json_number(p.magnitude / g)
      << ", \"t\": " << json_number(p.t_magnitude) << "}}";
  }
  j << "}},\n";
  j << "  \"car_crush\": {";
  for (std::size_t c = 0; c < cars_.size(); ++c) {
    const CarCrush& car = cars_[c];
    j << (c ? ", " : "") << json_string(car.car) << ": {\"max_crush\": " << json_number(car.max_crush)
      << ", \"t\": " << json_number(car.t) << ", \"elements\": [";
    for (std::size_t k = 0; k < car.elements.size(); ++k)
      j << (k ? ", " : "") << "{\"element\": " << json_string(car.elements[k]) << ", \"share\": " << json_number(car.shares[k]) << "}";
    j << "]}";
  }
  j << "}" << extra_json << "\n}\n";
  if (directory_.empty()) return j.str();
  std::ofstream out(directory_ + "/summary.json");
  out << j.str();
  if (!out) throw SolverError("could not write " + directory_ + "/summary.json");
  return j.str();
}

}  // namespace railcrash
