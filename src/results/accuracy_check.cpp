#include "railcrash/results/accuracy_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "railcrash/model/run_spec.hpp"
#include "railcrash/solver/dae_system.hpp"
#include "railcrash/solver/integrator.hpp"

namespace railcrash {

double relative_balance_error(const EnergyBalance& energy, double most_turned_over) {
  const double turned_over = std::max(energy.turned_over(), most_turned_over);
  return turned_over > 0.0 ? energy.error() / turned_over : 0.0;
}

AccuracyFacts accuracy_facts(const RunOutcome& outcome, const std::string& integrator, UnitSystem units) {
  AccuracyFacts facts;
  facts.relative_balance_error = relative_balance_error(EnergyBalance::between(outcome.initial_energy, outcome.final_energy),
                                                        outcome.most_energy_turned_over);
  facts.max_constraint_residual = outcome.max_constraint_residual;
  facts.units = units;
  facts.euler_ran = integrator == integrator_name(IntegratorKind::Euler) || outcome.stats.handed_over_at >= 0.0;
  facts.euler_step = outcome.stats.euler_step > 0.0 ? outcome.stats.euler_step : outcome.stats.last_step;
  facts.euler_from = outcome.stats.handed_over_at;
  facts.ida_took_back_at = outcome.stats.handed_back_at;
  facts.origin_distance_in_sizes = outcome.stats.origin_distance_in_sizes;
  return facts;
}

namespace {

std::string format(const char* pattern, double a, double b) {
  char text[256];
  std::snprintf(text, sizeof text, pattern, a, b);
  return text;
}

/// What to change, for the method that integrated the run.
std::string remedy(const AccuracyFacts& facts) {
  if (facts.euler_ran && facts.ida_took_back_at >= 0.0) {
    char text[400];
    std::snprintf(text, sizeof text,
                  "integrator auto ran Euler (steps of %.3g s) from t = %.6g to %.6g, where IDA took the run back: "
                  "run with --integrator ida to leave Euler out, or tighten IDA's tolerance (--rtol, --atol), and compare; "
                  "`railcrash converge` shows how the results move with it",
                  facts.euler_step, facts.euler_from, facts.ida_took_back_at);
    return text;
  }
  if (facts.euler_ran)
    return format("Euler's step was %.3g s: halve it (--dt %.3g) and compare, or run with --integrator ida; "
                  "`railcrash converge` shows how the results move with the step",
                  facts.euler_step, facts.euler_step / 2);
  return "tighten IDA's tolerance (--rtol, --atol) and compare; `railcrash converge` shows how the results move with it";
}

}  // namespace

std::vector<std::string> accuracy_warnings(const AccuracyFacts& facts) {
  std::vector<std::string> warnings;
  const double share = std::abs(facts.relative_balance_error);
  if (share > kEnergyShareLimit) {
    char text[160];
    std::snprintf(text, sizeof text, "the integration %s %.3g %% of the energy turned over (more than %.3g %%): ",
                  facts.relative_balance_error > 0 ? "created" : "lost", 100 * share, 100 * kEnergyShareLimit);
    warnings.push_back(text + remedy(facts));
  }
  const bool si = facts.units == UnitSystem::SI;
  const double limit = kConstraintResidualLimit / metres_per_length_unit(facts.units);  // [m] or [in]
  if (facts.max_constraint_residual > limit) {
    char text[200];
    std::snprintf(text, sizeof text, "joints open by up to %.3g %s at the output samples (more than %.3g %s): ",
                  facts.max_constraint_residual, si ? "m" : "in", limit, si ? "m" : "in");
    warnings.push_back(text + remedy(facts));
  }
  if (facts.origin_distance_in_sizes > kOriginDistanceLimit) {
    char text[400];
    std::snprintf(text, sizeof text,
                  "the model sits %.3g times its own size from its origin (more than %.3g): IDA's relative position "
                  "tolerance, rtol |q| + atol, grows with that distance and holds its positions that much more loosely "
                  "than at the origin: set simulation.position_tolerance: absolute (--set "
                  "simulation.position_tolerance=absolute), or move the model to its origin",
                  facts.origin_distance_in_sizes, kOriginDistanceLimit);
    warnings.push_back(text);
  }
  return warnings;
}

}  // namespace railcrash
