#include "support.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>

#include <unistd.h>

#include <catch2/catch.hpp>

#include "railcrash/model/model_io.hpp"
#include "railcrash/results/run.hpp"

namespace railcrash::testing {

std::filesystem::path temp_path(const std::string& name) {
  return std::filesystem::temp_directory_path() / (std::to_string(::getpid()) + "_" + name);
}

Model model_from_text(const std::string& yaml) { return load_model_text(yaml, "test.yaml").model; }

LoadedModel loaded_from_text(const std::string& yaml) { return load_model_text(yaml, "test.yaml"); }

double jacobian_error(const DaeSystem& system, double t, double cj, const std::vector<double>& y,
                      const std::vector<double>& yp, double* outside_pattern) {
  const int n = system.size();
  const SparsePattern& p = system.pattern();
  std::vector<double> values(static_cast<std::size_t>(p.nonzeros()));
  system.jacobian(t, cj, y.data(), yp.data(), values.data());
  // Dense copy of the analytic Jacobian.
  std::vector<double> analytic(static_cast<std::size_t>(n * n), 0.0);
  std::vector<bool> in_pattern(static_cast<std::size_t>(n * n), false);
  for (int c = 0; c < n; ++c)
    for (int k = p.column_start[static_cast<std::size_t>(c)]; k < p.column_start[static_cast<std::size_t>(c + 1)]; ++k) {
      const auto index = static_cast<std::size_t>(p.row_index[static_cast<std::size_t>(k)] * n + c);
      analytic[index] = values[static_cast<std::size_t>(k)];
      in_pattern[index] = true;
    }
  double worst = 0.0, outside = 0.0;
  std::vector<double> rp(static_cast<std::size_t>(n)), rm(rp.size());
  for (int c = 0; c < n; ++c) {
    // Perturb y_c and y'_c together: dF/dy + cj dF/dy' is the derivative along (1, cj).
    const double h = 1e-6 * std::max(1.0, std::abs(y[static_cast<std::size_t>(c)]));
    std::vector<double> y_plus = y, y_minus = y, yp_plus = yp, yp_minus = yp;
    y_plus[static_cast<std::size_t>(c)] += h;
    y_minus[static_cast<std::size_t>(c)] -= h;
    yp_plus[static_cast<std::size_t>(c)] += cj * h;
    yp_minus[static_cast<std::size_t>(c)] -= cj * h;
    system.residual(t, y_plus.data(), yp_plus.data(), rp.data());
    system.residual(t, y_minus.data(), yp_minus.data(), rm.data());
    for (int r = 0; r < n; ++r) {
      const double fd = (rp[static_cast<std::size_t>(r)] - rm[static_cast<std::size_t>(r)]) / (2.0 * h);
      const auto index = static_cast<std::size_t>(r * n + c);
      const double a = analytic[index];
      // Round-off floor of the difference quotient: residual entries of size |r| carry
      // about eps |r| of noise, divided by 2h.
      const double noise = 100.0 * std::numeric_limits<double>::epsilon() *
                           std::max({1.0, std::abs(rp[static_cast<std::size_t>(r)]), std::abs(rm[static_cast<std::size_t>(r)])}) / h;
      worst = std::max(worst, std::max(0.0, std::abs(fd - a) - noise) / std::max(1.0, std::abs(fd)));
      if (!in_pattern[index]) outside = std::max(outside, std::abs(fd));
    }
  }
  if (outside_pattern) *outside_pattern = outside;
  return worst;
}

RunOutcome simulate(const LoadedModel& loaded, double output_interval) {
  DaeSystem system(loaded.model);
  return simulate(system, loaded.run_spec.simulation, output_interval);
}

namespace {
RunOutcome run_quietly(DaeSystem& system, const SimulationSettings& simulation, double output_interval) {
  struct Quiet : RunObserver {
    void sample(double, const double*, const double*, const double*, const double*) override {}
  } observer;
  return make_integrator(system, simulation)->run(simulation.t_end, output_interval, observer);
}
}  // namespace

RunOutcome simulate(DaeSystem& system, const SimulationSettings& simulation, double output_interval) {
  RunOutcome outcome = run_quietly(system, simulation, output_interval);
  INFO(outcome.message);
  REQUIRE(outcome.ok);
  return outcome;
}

RunOutcome simulate_to_stop(const LoadedModel& loaded, double output_interval) {
  DaeSystem system(loaded.model);
  return run_quietly(system, loaded.run_spec.simulation, output_interval);
}

double message_time(const std::string& message) {
  const std::size_t at = message.find("at t = ");
  return at == std::string::npos ? std::numeric_limits<double>::quiet_NaN() : std::stod(message.substr(at + 7));
}

BodyState split(const DaeSystem& system, const std::vector<double>& y) {
  const auto nq = static_cast<std::ptrdiff_t>(system.body_unknowns());
  return {{y.begin(), y.begin() + nq}, {y.begin() + nq, y.begin() + 2 * nq}};
}

std::vector<double> forces(const DaeSystem& system, const BodyState& s) {
  std::vector<double> f(s.q.size(), 0.0);
  system.generalized_forces(0.0, s.q.data(), s.v.data(), f.data());
  return f;
}

std::vector<double> random_state(const DaeSystem& system, std::mt19937& rng, double spread) {
  std::uniform_real_distribution<double> u(-spread, spread);
  std::vector<double> y = system.initial_state();
  for (double& value : y) value += u(rng);
  return y;
}

std::string anticlimber_r1_model_text(double t_end) {
  const std::string path = std::string(RAILCRASH_SOURCE_DIR) + "/tests/models/anticlimber_r1.yaml";
  std::ifstream file(path);
  REQUIRE(file.good());
  std::ostringstream text;
  text << file.rdbuf();
  std::string model = text.str();
  char t_end_text[32];
  std::snprintf(t_end_text, sizeof t_end_text, "%g", t_end);
  const std::string default_end = "simulation: {t_end: 0.15,";
  const std::size_t at = model.find(default_end);
  REQUIRE(at != std::string::npos);
  return model.replace(at, default_end.size(), "simulation: {t_end: " + std::string(t_end_text) + ",");
}

}  // namespace railcrash::testing
