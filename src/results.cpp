#include "railcrash/results.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace railcrash {

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

ResultWriter::ResultWriter(const std::string& directory, const DaeSystem& system)
    : system_(system), directory_(directory), last_flush_(std::chrono::steady_clock::now()) {
  std::error_code error;
  std::filesystem::create_directories(directory, error);
  if (error) throw InputError("cannot create the output folder '" + directory + "': " + error.message());
  timeseries_ = std::fopen((directory + "/timeseries.csv").c_str(), "w");
  events_ = std::fopen((directory + "/events.csv").c_str(), "w");
  if (!timeseries_ || !events_) throw InputError("cannot write into the output folder '" + directory + "'");
  std::fputs("t", timeseries_);
  for (const Body& b : system.model().bodies())
    for (const char* q : {"x", "y", "theta", "vx", "vy", "omega"}) std::fprintf(timeseries_, ",%s.%s", b.name.c_str(), q);
  for (const std::string& name : system.output_names()) std::fprintf(timeseries_, ",%s", name.c_str());
  std::fputs("\n", timeseries_);
  std::fputs("t,element,event,value\n", events_);
  output_values_.assign(system.output_names().size(), 0.0);
  peak_output_.assign(system.output_names().size(), 0.0);
  peak_time_.assign(system.output_names().size(), 0.0);
}

ResultWriter::~ResultWriter() {
  if (timeseries_) std::fclose(timeseries_);
  if (events_) std::fclose(events_);
}

void ResultWriter::sample(double t, const double* y, const double* lambda, const double*) {
  const int n = system_.model().body_count();
  const int nq = 3 * n;
  std::fprintf(timeseries_, "%.12g", t);
  for (int i = 0; i < n; ++i)
    std::fprintf(timeseries_, ",%.12g,%.12g,%.12g,%.12g,%.12g,%.12g", y[3 * i], y[3 * i + 1], y[3 * i + 2], y[nq + 3 * i],
                 y[nq + 3 * i + 1], y[nq + 3 * i + 2]);
  system_.outputs(y, lambda, output_values_.data());
  for (std::size_t k = 0; k < output_values_.size(); ++k) {
    std::fprintf(timeseries_, ",%.12g", output_values_[k]);
    if (std::abs(output_values_[k]) > peak_output_[k]) {
      peak_output_[k] = std::abs(output_values_[k]);
      peak_time_[k] = t;
    }
  }
  std::fputs("\n", timeseries_);
  // Keep what is on disk current without flushing every row.
  const auto now = std::chrono::steady_clock::now();
  if (now - last_flush_ > std::chrono::milliseconds(500)) {
    std::fflush(timeseries_);
    std::fflush(events_);
    last_flush_ = now;
  }
}

void ResultWriter::event(const EventRecord& record, const double*) {
  std::string element = record.element, what = record.what;
  for (std::string* text : {&element, &what})
    if (text->find_first_of(",\"") != std::string::npos) {
      std::string quoted = "\"";
      for (char c : *text) quoted += (c == '"') ? std::string("\"\"") : std::string(1, c);
      *text = quoted + "\"";
    }
  std::fprintf(events_, "%.12g,%s,%s,%.12g\n", record.t, element.c_str(), what.c_str(), record.value);
}

void ResultWriter::write_summary(const RunOutcome& outcome, const std::string& integrator, const std::string& extra_json) {
  std::fflush(timeseries_);
  std::fflush(events_);
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
    << ", \"reinitializations\": " << s.reinitializations << ", \"wall_seconds\": " << json_number(s.wall_seconds)
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
  j << "}" << extra_json << "\n}\n";
  std::ofstream out(directory_ + "/summary.json");
  out << j.str();
  if (!out) throw SolverError("could not write " + directory_ + "/summary.json");
}

}  // namespace railcrash
