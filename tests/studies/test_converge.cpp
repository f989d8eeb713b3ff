#include <catch2/catch.hpp>

#include <cstdio>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

#include "railcrash/model/model_io.hpp"
#include "railcrash/results/cfc_filter.hpp"
#include "railcrash/results/run.hpp"
#include "railcrash/studies/converge.hpp"
#include "support.hpp"

using namespace railcrash;

namespace {

std::string case_path(const std::string& name) {
  return std::string(RAILCRASH_SOURCE_DIR) + "/verification/cases/" + name + ".yaml";
}

/// One run outside the study: body 0's (x, y) at every sample and the largest value of one output column
/// over the samples and the accepted steps.
struct Trace {
  std::vector<double> times, x, y;
  std::vector<double> values;  // the output column at every sample
  double peak = -1e300;
};

class TraceObserver : public RunObserver {
 public:
  TraceObserver(const DaeSystem& system, const std::string& column, Trace& trace)
      : system_(system), trace_(trace) {
    const auto& names = system.output_names();
    index_ = static_cast<std::size_t>(std::find(names.begin(), names.end(), column) - names.begin());
  }
  void sample(double t, const double* y, const double*, const double*, const double* outputs) override {
    trace_.times.push_back(t);
    trace_.x.push_back(y[0]);
    trace_.y.push_back(y[1]);
    if (index_ < system_.output_names().size()) {
      trace_.values.push_back(outputs[index_]);
      trace_.peak = std::max(trace_.peak, outputs[index_]);
    }
  }
  // The peak from every accepted step and both sides of every event as well (as `run` and
  // the study take it), so it does not depend on the output interval.
  void step(double, const double*, const double*, const double* outputs, const FreshOutputs& fresh) override {
    if (index_ < system_.output_names().size() && fresh.has(static_cast<int>(index_)))
      trace_.peak = std::max(trace_.peak, outputs[index_]);
  }
  bool observes_steps() const override { return true; }

 private:
  const DaeSystem& system_;
  Trace& trace_;
  std::size_t index_;
};

Trace run_by_hand(const std::string& path, const std::string& column, const std::vector<std::string>& settings) {
  const LoadedModel loaded = load_model(path, settings);
  const Model& model = loaded.model;
  DaeSystem system(model);
  Trace trace;
  TraceObserver observer(system, column, trace);
  const RunOutcome outcome =
      make_integrator(system, loaded.run_spec.simulation)->run(loaded.run_spec.simulation.t_end, output_interval_of(loaded.run_spec.simulation), observer);
  REQUIRE(outcome.ok);
  return trace;
}

/// The study on verification/cases/crush_impact.yaml over 0.1 s with 1e-4 s rows.
ConvergeResult crush_impact_study(const std::vector<std::string>& quantities, double euler_first_step, int euler_runs,
                                  double rtol) {
  ConvergeOptions options;
  options.quantities = quantities;
  options.t_end = 0.1;
  options.output_interval = 1e-4;
  options.euler_first_step = euler_first_step;
  options.euler_runs = euler_runs;
  options.rtols = {rtol};
  return run_convergence(plan_convergence(case_path("crush_impact"), options));
}

}  // namespace

TEST_CASE("convergence study: Euler first order and IDA errors falling with rtol on the damped spring-mass", "[converge]") {
  ConvergeOptions options;
  options.quantities = {"displacement_rms", "body.mass.x", "R1"};
  options.euler_first_step = 0.01;  // the output interval, so every run samples at the same times
  options.euler_runs = 5;
  options.rtols = {1e-3, 1e-4, 1e-5, 1e-6};
  const std::string path = case_path("damped_spring_mass");
  const ConvergePlan plan = plan_convergence(path, options);
  REQUIRE(plan.euler_steps.size() == 5);
  CHECK(plan.euler_steps[4] == Approx(0.01 / 16));
  CHECK(plan.headline == 0);
  // R1 does not apply: reported as such, never as a number.
  REQUIRE_FALSE(plan.quantities[2].applicable);
  CHECK_THAT(plan.quantities[2].note, Catch::Contains("no responses section"));

  const ConvergeResult result = run_convergence(plan);
  REQUIRE(result.reference.ok);
  REQUIRE(result.euler.size() == 5);
  REQUIRE(result.ida.size() == 4);
  for (const auto* runs : {&result.euler, &result.ida})
    for (const ConvergeRun& run : *runs) {
      REQUIRE(run.ok);
      CHECK(std::isnan(run.values[2]));
      CHECK(std::isnan(run.errors[2]));
    }
  // The reference against the closed form: x - L0 = A e^(-zeta w t) (cos wd t + zeta w / wd sin wd t).
  const double omega = 10.0, zeta = 0.1, amplitude = 0.1, t_end = 3.0;
  const double wd = omega * std::sqrt(1.0 - zeta * zeta);
  const double exact = amplitude * std::exp(-zeta * omega * t_end) * (std::cos(wd * t_end) + zeta * omega / wd * std::sin(wd * t_end));
  CHECK(result.reference.values[1] == Approx(exact - amplitude).margin(1e-7));

  // Explicit Euler (velocity first) with damping is first order in the trajectory.
  CHECK(result.euler_order[0].points == 5);
  CHECK(result.euler_order[0].slope > 0.8);
  CHECK(result.euler_order[0].slope < 1.2);
  // IDA: the trajectory error falls with every tenfold tighter tolerance.
  for (std::size_t k = 1; k < result.ida.size(); ++k) CHECK(result.ida[k].errors[0] < result.ida[k - 1].errors[0]);
  CHECK(result.ida_rtol_slope[0].slope > 0.5);

  // One error by hand, from two runs made outside the study (dt = 0.0025 samples at the same times).
  const Trace reference = run_by_hand(path, "", {"simulation.rtol=1e-9", "simulation.integrator=ida"});
  const Trace euler = run_by_hand(path, "", {"simulation.integrator=euler", "simulation.dt=0.0025"});
  REQUIRE(euler.times.size() == reference.times.size());
  double sum = 0.0, largest = 0.0;
  for (std::size_t i = 0; i < reference.times.size(); ++i) {
    REQUIRE(euler.times[i] == Approx(reference.times[i]).margin(1e-12));
    const double dx = (euler.x[i] - euler.x[0]) - (reference.x[i] - reference.x[0]);
    const double dy = (euler.y[i] - euler.y[0]) - (reference.y[i] - reference.y[0]);
    sum += dx * dx + dy * dy;
    largest = std::max({largest, std::abs(reference.x[i] - reference.x[0]), std::abs(reference.y[i] - reference.y[0])});
  }
  const double rms = std::sqrt(sum / (2.0 * static_cast<double>(reference.times.size())));
  CHECK(result.euler[2].step == Approx(0.0025));
  CHECK(result.euler[2].values[0] == Approx(rms).epsilon(1e-6));
  CHECK(result.euler[2].errors[0] == Approx(rms / largest).epsilon(1e-6));
  // body.mass.x: end displacement, error over the reference's largest x displacement.
  const double end_error = std::abs((euler.x.back() - euler.x[0]) - (reference.x.back() - reference.x[0])) / largest;
  CHECK(result.euler[2].errors[1] == Approx(end_error).epsilon(1e-6));
}

TEST_CASE("convergence study: peak crush against the closed form and an Euler error by hand", "[converge]") {
  // 100 kg at 10 m/s into an elastic-perfectly-plastic crush structure: largest crush 0.055 m
  // (closed form in verification/cases/crush_impact.yaml), largest force F0 = 100 kN.
  const std::string path = case_path("crush_impact");
  const ConvergeResult result =
      crush_impact_study({"max_crush", "element.crush.force", "peak_anticlimber_force"}, 1e-4, 2, 1e-5);
  REQUIRE(result.reference.ok);
  CHECK(result.reference.values[0] == Approx(0.055).epsilon(1e-4));
  CHECK(result.reference.values[1] == Approx(1e5).epsilon(1e-6));
  CHECK_FALSE(result.quantities[2].applicable);
  CHECK(result.reference.errors[0] == 0.0);

  const Trace reference =
      run_by_hand(path, "crush.crush", {"simulation.t_end=0.1", "simulation.output_interval=1e-4", "simulation.rtol=1e-9"});
  const Trace euler = run_by_hand(
      path, "crush.crush",
      {"simulation.t_end=0.1", "simulation.output_interval=1e-4", "simulation.integrator=euler", "simulation.dt=5e-5"});
  REQUIRE(result.euler[1].ok);
  CHECK(result.euler[1].values[0] == Approx(euler.peak).epsilon(1e-12));
  CHECK(result.euler[1].errors[0] == Approx(std::abs(euler.peak - reference.peak) / reference.peak).epsilon(1e-6));
}

TEST_CASE("convergence study: event times and the CFC-60 acceleration against the closed form", "[converge]") {
  // crush_impact: 100 kg at 10 m/s closes a 0.5 m gap (contact at 0.05 s), loads elastically
  // (k = 1e7 N/m, w = sqrt(k / m)) to 10 mm, where x = (v0 / w) sin(w t1) gives
  // t1 = asin(0.01 w / v0) / w and v1 = v0 cos(w t1), then crushes at F0 = 100 kN until it
  // stops, t2 = m v1 / F0 later, and unloads. The crushing deceleration is F0 / m = 1000 m/s^2.
  const std::string path = case_path("crush_impact");
  const ConvergeResult result =
      crush_impact_study({"event.crush:contact", "event.crush:unloading", "acceleration.mass"}, 1e-5, 1, 1e-4);
  REQUIRE(result.reference.ok);
  const double omega = std::sqrt(1e7 / 100.0), v0 = 10.0;
  const double t1 = std::asin(0.01 * omega / v0) / omega, v1 = v0 * std::cos(omega * t1);
  CHECK(result.reference.values[0] == Approx(0.05).margin(1e-9));
  CHECK(result.reference.values[1] == Approx(0.05 + t1 + 100.0 * v1 / 1e5).margin(1e-8));
  // The errors are over the reference's event time; both other runs have both events.
  for (const ConvergeRun* run : {&result.euler[0], &result.ida[0]}) {
    REQUIRE(run->ok);
    CHECK(run->errors[1] == Approx(std::abs(run->values[1] - result.reference.values[1]) / result.reference.values[1]));
    CHECK(run->errors[1] < 1e-2);
  }

  // The acceleration by hand: the crush force over the mass at every 1e-4 s sample (not the
  // body accelerations the study filters), filtered at CFC 60, in g.
  const Trace force =
      run_by_hand(path, "crush.force", {"simulation.t_end=0.1", "simulation.output_interval=1e-4", "simulation.rtol=1e-9"});
  std::vector<double> acceleration;  // [m/s^2]
  for (double f : force.values) acceleration.push_back(f / 100.0);
  double peak = 0.0;
  for (double a : cfc::filter(acceleration, 1e-4, 60.0)) peak = std::max(peak, std::abs(a));
  CHECK(result.reference.values[2] == Approx(peak / 9.80665).epsilon(1e-4));
  // The filtered plateau is the crushing deceleration, 101.97 g, and a filter overshoot of a few %.
  CHECK(result.reference.values[2] > 1000.0 / 9.80665);
  CHECK(result.reference.values[2] < 1.06 * 1000.0 / 9.80665);
}

TEST_CASE("convergence study: unknown quantities are input errors that say what to write", "[converge]") {
  const std::string path = case_path("damped_spring_mass");
  ConvergeOptions options;
  options.euler_runs = 0;
  options.quantities = {"max_crunch"};
  CHECK_THROWS_WITH(plan_convergence(path, options), Catch::Contains("unknown quantity 'max_crunch'") &&
                                                         Catch::Contains("element.NAME.OUTPUT"));
  options.quantities = {"element.nope.force"};
  CHECK_THROWS_AS(plan_convergence(path, options), InputError);
  CHECK_THROWS_WITH(plan_convergence(path, options), Catch::Contains("no element named 'nope'"));
  options.quantities = {"element.spring.torque"};
  CHECK_THROWS_WITH(plan_convergence(path, options), Catch::Contains("has no output 'torque'") && Catch::Contains("force"));
  options.quantities = {"body.mass.z"};
  CHECK_THROWS_AS(plan_convergence(path, options), InputError);
  options.quantities = {"event.nope:contact"};
  CHECK_THROWS_WITH(plan_convergence(path, options), Catch::Contains("no element named 'nope'") && Catch::Contains("event.NAME:TEXT"));
  options.quantities = {"acceleration.nope"};
  CHECK_THROWS_WITH(plan_convergence(path, options), Catch::Contains("no body named 'nope'"));
  options.quantities = {"acceleration.mass"};
  options.output_interval = 0.01;  // 100 rows per second: too few for CFC 60
  CHECK_THROWS_WITH(plan_convergence(path, options), Catch::Contains("CFC 60") && Catch::Contains("--output-interval"));
  options.output_interval.reset();
  options.quantities = {"R2", "displacement_rms"};
  options.headline = "R2";
  CHECK_THROWS_WITH(plan_convergence(path, options), Catch::Contains("does not apply"));
  options.headline.clear();
  options.rtols = {1e-3, 1e-10};
  CHECK_THROWS_WITH(plan_convergence(path, options), Catch::Contains("not looser than the reference"));
}

namespace {
std::string four_digits(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.4g", value);
  return buffer;
}
}  // namespace

TEST_CASE("convergence study: log-log slope and the files written", "[converge]") {
  // y = 3 x^1.5 exactly; the zero and NaN points are left out of the fit.
  const std::vector<double> x{1e-3, 2e-3, 4e-3, 8e-3, 1.0};
  const std::vector<double> y{3 * std::pow(1e-3, 1.5), 3 * std::pow(2e-3, 1.5), 3 * std::pow(4e-3, 1.5), 0.0, std::nan("")};
  const ConvergeFit fit = log_log_slope(x, y);
  CHECK(fit.points == 3);
  CHECK(fit.slope == Approx(1.5).epsilon(1e-12));
  CHECK(std::isnan(log_log_slope({1.0}, {2.0}).slope));

  ConvergeOptions options;
  options.quantities = {"displacement_rms"};
  options.euler_first_step = 0.01;
  options.euler_runs = 2;
  options.rtols = {1e-4};
  options.t_end = 0.5;
  options.jobs = 2;
  const ConvergeResult result = run_convergence(plan_convergence(case_path("damped_spring_mass"), options));
  const std::string dir = (testing::temp_path("railcrash_converge_test")).string();
  std::filesystem::remove_all(dir);
  const std::string md = write_convergence(result, dir);
  CHECK_THAT(md, Catch::Contains("Observed orders"));
  // With the first Euler step given the elements' limit is not computed: the header states the
  // limit it has as a sentence of its own (it once read "s in all., with the penalty joints").
  REQUIRE(result.stability_limit > 0.0);
  REQUIRE(result.element_stability_limit == 0.0);
  const std::string header_line = md.substr(0, md.find('\n'));
  CHECK_THAT(header_line, Catch::EndsWith(" s in all. Euler stability limit with the penalty joints at the first step " +
                                          four_digits(result.stability_limit) + " s."));
  std::ifstream csv(dir + "/converge.csv");
  std::string header, line;
  std::getline(csv, header);
  CHECK(header == "method,step,rtol,status,wall_s,steps,residual_evaluations,jacobian_evaluations,events,"
                  "displacement_rms,displacement_rms_error,message,outcomes,branch,integrator_used,euler_from_t");
  int rows = 0;
  while (std::getline(csv, line)) {
    ++rows;
    // The method each run used (the study names ida for the reference and IDA runs, euler for Euler's).
    const std::string method = line.substr(0, line.find(','));
    CHECK_THAT(line, Catch::EndsWith(std::string(",") + (method == "euler" ? "euler" : "ida") + ","));
  }
  CHECK(rows == 4);  // reference, two Euler, one IDA
  CHECK(std::filesystem::file_size(dir + "/converge.svg") > 0);
  std::filesystem::remove_all(dir);
}

TEST_CASE("convergence study: a run over its time limit is stopped and reported failed", "[converge]") {
  ConvergeOptions options;
  options.quantities = {"displacement_rms"};
  options.t_end = 1.0;
  options.euler_first_step = 1e-7;  // ten million steps, the --max-steps default: about 1 s in a Release build here
  options.euler_runs = 1;
  options.rtols = {1e-4};
  // A quarter of that: with a limit of 1 s the Euler run (0.98 s alone) sometimes finished
  // in time. The IDA runs take under a millisecond (tens of milliseconds under ASan).
  options.run_time_limit = 0.25;
  const ConvergeResult result = run_convergence(plan_convergence(case_path("damped_spring_mass"), options));
  REQUIRE(result.euler.size() == 1);
  CHECK_FALSE(result.euler[0].ok);
  CHECK_THAT(result.euler[0].message, Catch::Contains("run time limit of 0.25 s"));
  CHECK(result.euler[0].wall_seconds < 10.0);
  CHECK(std::isnan(result.euler[0].errors[0]));
  CHECK(result.reference.ok);
  CHECK(result.ida[0].ok);
}

TEST_CASE("convergence study: max_crush and the peak forces take the same columns by role as by element type before", "[converge]") {
  // Before the output roles, converge picked the columns by element type: max_crush from
  // crush_spring crush and anticlimber horizontal_deformation, peak_anticlimber_force from
  // anticlimber horizontal_force, peak_coupler_force from coupler_end normal_force and
  // coupling horizontal_force. The report model (its max_crush is R1's measure, from the
  // responses section) and the barrier model (crush springs, a coupler_end) must keep them.
  ConvergeOptions options;
  options.euler_runs = 0;
  options.quantities = {"max_crush", "peak_anticlimber_force", "peak_coupler_force"};
  for (const char* file : {"/models/report/final_two_car.yaml", "/models/barrier/two_car_barrier.yaml"}) {
    const std::string path = std::string(RAILCRASH_SOURCE_DIR) + file;
    INFO(path);
    const ConvergePlan plan = plan_convergence(path, options);
    const LoadedModel loaded = load_model(path);
    const Model& model = loaded.model;
    DaeSystem system(model);
    const auto by_type = [&](const std::vector<std::pair<std::string, std::string>>& type_outputs) {
      std::set<int> columns;
      const auto& names = system.output_names();
      for (const auto& e : model.elements())
        for (const auto& [type, output] : type_outputs)
          if (e->type() == type)
            columns.insert(static_cast<int>(std::find(names.begin(), names.end(), e->name() + "." + output) - names.begin()));
      return columns;
    };
    const auto columns = [&](std::size_t q) { return std::set<int>(plan.quantities[q].columns.begin(), plan.quantities[q].columns.end()); };
    const bool from_responses = loaded.run_spec.responses.crush_from_anticlimber || !loaded.run_spec.responses.crush_gauges.empty();
    CHECK(plan.quantities[0].from_responses == from_responses);
    CHECK(columns(0) == (from_responses ? std::set<int>{}
                                        : by_type({{"crush_spring", "crush"}, {"anticlimber", "horizontal_deformation"}})));
    CHECK(columns(1) == by_type({{"anticlimber", "horizontal_force"}}));
    CHECK(columns(2) == by_type({{"coupler_end", "normal_force"}, {"coupling", "horizontal_force"}}));
    CHECK(plan.quantities[0].applicable);
    CHECK(plan.quantities[2].applicable);
  }
}

TEST_CASE("convergence study: a level counts only from the setting on which every tighter one meets it", "[converge]") {
  // IDA runs, loosest first: errors 1e-2, 1e-4 (met by luck), 5e-3 (missed again), 1e-5.
  std::vector<ConvergeRun> runs;
  const double rtols[] = {1e-3, 1e-4, 1e-5, 1e-6}, seconds[] = {1.0, 2.0, 3.0, 4.0}, errors[] = {1e-2, 1e-4, 5e-3, 1e-5};
  for (int k = 3; k >= 0; --k) {  // in any order: the setting decides what is tighter
    ConvergeRun r;
    r.method = "ida";
    r.rtol = rtols[k];
    r.ok = true;
    r.wall_seconds = seconds[k];
    r.errors = {errors[k]};
    runs.push_back(r);
  }
  // 1e-3: between the 5e-3 run (3 s) and the 1e-5 run (4 s), log-log, not between the first two.
  const TimeAtLevel at = time_at_level(runs, 0, 1e-3);
  CHECK(at.how == "interpolated");
  const double expected = std::exp(std::log(3.0) + (std::log(1e-3) - std::log(5e-3)) * (std::log(4.0) - std::log(3.0)) /
                                                       (std::log(1e-5) - std::log(5e-3)));
  CHECK(at.seconds == Approx(expected).epsilon(1e-12));
  // 2e-2: every run meets it, the cheapest bounds it.
  const TimeAtLevel loose = time_at_level(runs, 0, 2e-2);
  CHECK(loose.how == "<=");
  CHECK(loose.seconds == 1.0);
  // A failed tight run does not count either way: 1e-6 is then extrapolated from the others.
  runs.front().ok = false;  // the rtol 1e-6 run
  CHECK(time_at_level(runs, 0, 1e-3).how == "extrapolated");
}

TEST_CASE("convergence study: a bad reference tolerance is refused offering a reference's value", "[converge]") {
  // The one rtol message (rtol_problem), with the typical value a reference run wants: 1e-9, not
  // a run's 1e-6 (the hint --reference-rtol had before the messages were made one).
  ConvergeOptions options;
  options.euler_runs = 0;
  options.reference_rtol = -1e-9;
  CHECK_THROWS_WITH(plan_convergence(case_path("damped_spring_mass"), options),
                    "--reference-rtol must be a positive number (the relative tolerance; typical: 1e-9), not -1e-09");
  options.reference_rtol = 1e-9;
  options.rtols = {1e-3, 0.0};
  CHECK_THROWS_WITH(plan_convergence(case_path("damped_spring_mass"), options),
                    "--rtols: every tolerance must be a positive number (the relative tolerance; typical: 1e-6), not 0");
}
