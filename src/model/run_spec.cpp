// The run's settings' names and checks (see the header).
#include "railcrash/model/run_spec.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

namespace railcrash {

std::optional<IntegratorKind> integrator_from_name(const std::string& name) {
  for (const IntegratorName& entry : kIntegratorNames)
    if (name == entry.name) return entry.kind;
  return std::nullopt;
}

std::vector<std::string> integrator_names() {
  std::vector<std::string> names;
  for (const IntegratorName& entry : kIntegratorNames) names.emplace_back(entry.name);
  return names;
}

std::string integrator_names_text(const std::string& quote) {
  const std::vector<std::string> names = integrator_names();
  std::string text;
  for (std::size_t k = 0; k < names.size(); ++k)
    text += (k == 0 ? "" : k + 1 == names.size() ? " or " : ", ") + quote + names[k] + quote;
  return text;
}

std::string rtol_problem(double rtol, const std::string& what, const char* typical) {
  if (rtol > 0.0 && std::isfinite(rtol)) return "";
  char value[32];
  std::snprintf(value, sizeof value, "%g", rtol);
  return what + " must be a positive number (the relative tolerance; typical: " + typical + "), not " + value;
}

std::string output_rows_problem(const SimulationSettings& settings) {
  if (!(settings.output_interval > 0.0)) return "";  // the default, t_end / 500
  const double rows = settings.t_end / settings.output_interval;  // [rows]
  if (rows <= kMaxOutputRows) return "";
  std::ostringstream msg;
  msg << "output_interval " << settings.output_interval << " with t_end " << settings.t_end << " gives " << rows
      << " output rows, more than the limit " << kMaxOutputRows << "; use output_interval >= "
      << settings.t_end / kMaxOutputRows;
  return msg.str();
}

}  // namespace railcrash
