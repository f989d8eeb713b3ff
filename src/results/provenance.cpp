// A run's provenance (see the header).
#include "railcrash/results/provenance.hpp"

#include <random>

#include "railcrash/core/version.hpp"
#include "railcrash/results/results.hpp"
#include "railcrash/results/run.hpp"

namespace railcrash {

namespace {

std::string& kept_command_line() {
  static std::string text;
  return text;
}

/// An argument as a POSIX shell reads it back: as it is when it holds only safe characters, else in single quotes.
std::string shell_quoted(const std::string& argument) {
  const bool safe = !argument.empty() && argument.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                                                    "0123456789_-+=./,:@%") == std::string::npos;
  if (safe) return argument;
  std::string out = "'";
  for (const char c : argument) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

}  // namespace

std::string new_run_id() {
  std::random_device device;
  static const char* const kHex = "0123456789abcdef";
  std::string id;
  for (int word = 0; word < 4; ++word) {
    const std::uint32_t bits = device();
    for (int shift = 28; shift >= 0; shift -= 4) id += kHex[(bits >> shift) & 0xF];
  }
  return id;
}

void set_command_line(int argc, const char* const* argv) {
  std::string text;
  for (int k = 0; k < argc; ++k) text += (k ? " " : "") + shell_quoted(argv[k]);
  kept_command_line() = text;
}

const std::string& command_line() { return kept_command_line(); }

Provenance run_provenance(const Model& model, const SimulationSettings& simulation, const std::string& run_id) {
  Provenance p;
  p.run_id = run_id;
  p.version = version_number();
  p.commit = build_commit();
  p.command_line = command_line();
  p.model_files = model.sources;
  p.settings = model.settings;
  p.simulation = simulation;
  return p;
}

std::string provenance_json(const Provenance& p) {
  std::string j = "{\"run_id\": " + json_string(p.run_id) + ", \"version\": " + json_string(p.version) +
                  ", \"commit\": " + json_string(p.commit) + ", \"command_line\": " + json_string(p.command_line) +
                  ", \"model_files\": [";
  for (std::size_t k = 0; k < p.model_files.size(); ++k)
    j += std::string(k ? ", " : "") + "{\"path\": " + json_string(p.model_files[k].path) + ", \"sha256\": " +
         json_string(p.model_files[k].sha256) + "}";
  j += "], \"settings\": [";
  for (std::size_t k = 0; k < p.settings.size(); ++k) j += std::string(k ? ", " : "") + json_string(p.settings[k]);
  const SimulationSettings& s = p.simulation;
  const bool euler = s.integrator != IntegratorKind::Ida, ida = s.integrator != IntegratorKind::Euler;
  j += "], \"simulation\": {\"integrator\": " + json_string(integrator_name(s.integrator)) + ", \"t_end\": " + json_number(s.t_end) +
       ", \"output_interval\": " + json_number(output_interval_of(s)) + ", \"max_steps\": " + std::to_string(s.max_steps);
  if (euler)
    j += ", \"dt\": " + (s.dt > 0.0 ? json_number(s.dt) : "\"0.5 x stability limit\"") +
         ", \"force_dt\": " + (s.force_dt ? "true" : "false");
  if (ida) {
    j += ", \"rtol\": " + json_number(s.rtol) + ", \"atol\": " + (s.atol ? json_number(*s.atol) : "\"from the model\"");
    if (s.position_tolerance == PositionTolerance::Absolute) j += ", \"position_tolerance\": \"absolute\"";
    if (s.linear_ordering != LinearOrdering::FewestEntries)
      j += std::string(", \"linear_ordering\": ") + (s.linear_ordering == LinearOrdering::Amd ? "\"amd\"" : "\"colamd\"");
    if (s.jacobian_kept_steps != SimulationSettings{}.jacobian_kept_steps)
      j += ", \"jacobian_kept_steps\": " + std::to_string(s.jacobian_kept_steps);
  }
  j += std::string(", \"static_equilibrium\": ") + (s.static_equilibrium ? "true" : "false") + "}}";
  return j;
}

std::string provenance_comment(const Provenance& provenance) {
  return "# railcrash provenance " + provenance_json(provenance) + "\n";
}

std::optional<std::string> run_id_in(const std::string& text) {
  const std::string key = "\"run_id\": \"";  // (found by find: a summary.json may be megabytes long)
  const std::size_t at = text.find(key);
  if (at == std::string::npos) return std::nullopt;
  const std::size_t start = at + key.size(), end = text.find('"', start);
  if (end == std::string::npos) return std::nullopt;
  return text.substr(start, end - start);
}

}  // namespace railcrash
