// Uses railcrash as a library (include/railcrash/api.hpp): builds a spring-mass oscillator in
// code, runs it in memory, and compares its period with the closed form T = 2 pi sqrt(m / k);
// then loads a model file given on the command line, scales a parameter and runs it.
//
//   spring_mass [MODEL.yaml [SETTING ...]]
//
// Exit status 0 when the period matches to 1e-5 (relative) and the errors below are reported
// as they should be; 1 otherwise.
#include <railcrash/api.hpp>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace rc = railcrash::api;

namespace {

/// Mean period [s] of a signal from its upward crossings of `level` (linear interpolation).
double mean_period(const std::vector<double>& t, const std::vector<double>& x, double level) {
  std::vector<double> crossings;
  for (std::size_t k = 1; k < t.size(); ++k)
    if (x[k - 1] < level && x[k] >= level)
      crossings.push_back(t[k - 1] + (level - x[k - 1]) / (x[k] - x[k - 1]) * (t[k] - t[k - 1]));
  if (crossings.size() < 2) return NAN;
  return (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
}

}  // namespace

int main(int argc, char** argv) {
  std::printf("railcrash %s\n", rc::version());
  bool ok = true;

  // A 2 kg cart on a 800 N/m spring, released 0.1 m from its free length.
  const double mass = 2.0;         // [kg]
  const double stiffness = 800.0;  // [N/m]
  rc::ModelBuilder builder("spring-mass", "SI");
  builder.gravity(0.0, 0.0);
  builder.body({"cart", mass, 0.1, 1.1, 0.0});
  builder.element("spring", "linear_spring", {{"ground", 0.0, 0.0}, {"cart", 0.0, 0.0}},
                  {{"stiffness", stiffness}, {"free_length", 1.0}});
  rc::RunSettings simulation;
  simulation.t_end = 1.0;
  simulation.output_interval = 1e-4;
  builder.simulation(simulation);
  const rc::Model model = builder.build();

  rc::RunSettings settings;
  settings.integrator = "ida";
  settings.rtol = 1e-9;
  const rc::Results results = rc::run(model, settings);
  const double period = mean_period(results.t(), results.series("cart.x"), 1.0);
  const double exact = 2.0 * M_PI * std::sqrt(mass / stiffness);
  const double relative_error = std::abs(period - exact) / exact;
  std::printf("spring-mass: %zu samples, period %.8f s, closed form %.8f s, relative error %.2e, energy balance error %.2e J\n",
              results.t().size(), period, exact, relative_error, results.summary.energy_balance_error);
  ok = ok && results.ok() && relative_error < 1e-5;

  // The same model, stiffer by 4x through a setting: the period halves.
  const rc::Results stiffer = rc::run(model.with({"elements.spring.stiffness*=4"}), settings);
  const double stiffer_period = mean_period(stiffer.t(), stiffer.series("cart.x"), 1.0);
  std::printf("stiffness x4: period %.8f s (ratio %.6f, closed form 0.5)\n", stiffer_period, stiffer_period / period);
  ok = ok && std::abs(stiffer_period / period - 0.5) < 1e-5;

  // Bad input is an InputError that names what to change.
  try {
    rc::ModelBuilder dangling("dangling", "SI");
    dangling.body({"cart", 1.0, 0.1, 1.0, 0.0});
    dangling.element("spring", "linear_spring", {{"ground", 0.0, 0.0}, {"crat", 0.0, 0.0}}, {{"stiffness", 10.0}});
    dangling.build();
    std::printf("a dangling body name was accepted\n");
    ok = false;
  } catch (const railcrash::InputError& e) {
    std::printf("dangling body name: %s\n", e.what());
    ok = ok && std::string(e.what()).find("crat") != std::string::npos;
  }

  if (argc > 1) {
    const std::vector<std::string> model_settings(argv + 2, argv + argc);
    const rc::Model file_model = rc::Model::load(argv[1], model_settings);
    rc::RunSettings fast;
    fast.rtol = 1e-4;
    const rc::Results run = rc::run(file_model, fast);
    std::printf("%s: %s, t = %g s, %zu samples, %zu events, %ld steps\n", file_model.name().c_str(),
                run.ok() ? "ok" : run.summary.message.c_str(), run.summary.t_reached, run.t().size(), run.events.size(),
                run.summary.steps);
    for (const rc::CarCrush& car : run.summary.cars) std::printf("  %s max crush %.4g at t = %.4g s\n", car.car.c_str(), car.max_crush, car.t);
    ok = ok && run.ok();
  }
  std::printf("%s\n", ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
}
