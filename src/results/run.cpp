#include "railcrash/results/run.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <sstream>

#include "railcrash/core/progress.hpp"
#include "railcrash/results/responses.hpp"
#include "railcrash/results/results.hpp"
#include "railcrash/results/scenario_criteria.hpp"
#include "railcrash/solver/auto_integrator.hpp"
#include "railcrash/solver/euler_integrator.hpp"
#include "railcrash/solver/ida_integrator.hpp"

namespace railcrash {

namespace {

std::string number_text(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

/// Forwards samples to the writer and the response tracker (if any) and shows progress
/// (progress.hpp: a bar on a terminal, a line every few seconds otherwise).
/// Also checks every sample's element outputs: from the first non-finite one on, no sample is passed on.
class ProgressObserver : public RunObserver {
 public:
  ProgressObserver(const DaeSystem& system, std::vector<RunObserver*> next, double t_end, bool show)
      : system_(system), next_(std::move(next)), meter_(t_end, ProgressMeter::style_for(show, stderr)) {}
  /// From the first sample whose element outputs are not all finite on, nothing is passed on:
  /// the files end at the last good sample. The run itself goes on, so that an integrator that
  /// is diverging says so (Euler names the joint); run_model fails it in any case.
  void sample(double t, const double* y, const double* lambda, const double* quadratures, const double* outputs) override {
    pass_on(t, y, lambda, quadratures, outputs, nullptr);
  }
  bool wants_sample_forces() const override {
    return std::any_of(next_.begin(), next_.end(), [](const RunObserver* o) { return o->wants_sample_forces(); });
  }
  void sample_with_forces(double t, const double* y, const double* lambda, const double* quadratures, const double* outputs,
                          const double* forces) override {
    pass_on(t, y, lambda, quadratures, outputs, forces);
  }
  /// Why the outputs were not all finite ("" when they were).
  const std::string& non_finite_output() const { return non_finite_output_; }
  /// The last sample passed on to the writers (-1: none).
  double last_sample_passed_on() const { return t_passed_on_; }

  void event(const EventRecord& record, const double* y) override {
    for (RunObserver* o : next_) o->event(record, y);
  }
  /// Steps are passed on while the samples are (the extrema end where the files do).
  void step(double t, const double* y, const double* lambda, const double* outputs, const FreshOutputs& fresh) override {
    if (non_finite_output_.empty())
      for (RunObserver* o : next_) o->step(t, y, lambda, outputs, fresh);
  }
  bool observes_steps() const override {
    return std::any_of(next_.begin(), next_.end(), [](const RunObserver* o) { return o->observes_steps(); });
  }
  /// The columns of every observer that takes steps.
  void mark_step_columns(std::vector<char>& columns) const override {
    for (const RunObserver* o : next_)
      if (o->observes_steps()) o->mark_step_columns(columns);
  }
  std::string failure() const override {
    for (const RunObserver* o : next_)
      if (std::string why = o->failure(); !why.empty()) return why;
    return "";
  }

  void finish() { meter_.finish(t_last_); }

 private:
  /// The sample to every observer, with the forces when given (an observer that does not want
  /// them gets sample() through RunObserver::sample_with_forces' default).
  void pass_on(double t, const double* y, const double* lambda, const double* quadratures, const double* outputs,
               const double* forces) {
    meter_.update(t);
    t_last_ = t;
    if (!non_finite_output_.empty() || !outputs_finite(t, outputs)) return;
    for (RunObserver* o : next_) {
      if (forces != nullptr)
        o->sample_with_forces(t, y, lambda, quadratures, outputs, forces);
      else
        o->sample(t, y, lambda, quadratures, outputs);
    }
    t_passed_on_ = t;
  }

  /// Whether the element outputs at the sample are all finite; the first non-finite one is
  /// recorded in non_finite_output_ (its element found only then).
  bool outputs_finite(double t, const double* outputs) {
    const auto& names = system_.output_names();
    const auto bad = std::find_if(outputs, outputs + names.size(), [](double value) { return !std::isfinite(value); });
    if (bad == outputs + names.size()) return true;
    const std::size_t column = static_cast<std::size_t>(bad - outputs);
    std::size_t first_of_element = 0;  // column of the element's first output
    for (const auto& el : system_.model().elements()) {
      const std::vector<std::string> own = el->output_names();
      if (column < first_of_element + own.size()) {
        std::ostringstream msg;
        msg << el->where().prefix() << "element '" << el->name() << "' (" << el->type() << "): its output '"
            << own[column - first_of_element] << "' is " << *bad << " at t = " << t
            << "; check the element's numbers (a value too large or too small)";
        non_finite_output_ = msg.str();
        return false;
      }
      first_of_element += own.size();
    }
    RAILCRASH_DEMAND(false);  // every output column belongs to an element
    return false;
  }

  const DaeSystem& system_;
  std::vector<RunObserver*> next_;
  ProgressMeter meter_;
  std::string non_finite_output_;
  double t_last_ = 0.0;
  double t_passed_on_ = -1.0;
};

}  // namespace

std::vector<OptionSetting> option_settings(const RunOverrides& o, OverrideSource source) {
  std::vector<OptionSetting> settings;
  // `flag`: the option takes no value (--force-dt).
  const auto add = [&](const char* key, const char* option, const std::string& value, bool flag = false) {
    std::string label;
    switch (source) {
      case OverrideSource::CommandLine: label = flag ? std::string(option) : std::string(option) + " " + value; break;
      case OverrideSource::RunSettings: label = std::string("RunSettings.") + key + " = " + value; break;
      case OverrideSource::ConvergeRun: label = std::string("converge run's ") + key + " " + value; break;
    }
    settings.push_back({std::string("simulation.") + key + "=" + value, label});
  };
  const auto number = [](double value) {  // the shortest text that reads back as the same double
    char text[40];
    for (int digits = 15; digits <= 17; ++digits) {
      std::snprintf(text, sizeof text, "%.*g", digits, value);
      if (std::strtod(text, nullptr) == value) break;
    }
    return std::string(text);
  };
  if (o.integrator) add("integrator", "--integrator", integrator_name(*o.integrator));
  if (o.t_end) add("t_end", "--t-end", number(*o.t_end));
  if (o.rtol) add("rtol", "--rtol", number(*o.rtol));
  if (o.atol) add("atol", "--atol", number(*o.atol));
  if (o.dt) add("dt", "--dt", number(*o.dt));
  if (o.output_interval) add("output_interval", "--output-interval", number(*o.output_interval));
  if (o.max_steps) add("max_steps", "--max-steps", std::to_string(*o.max_steps));
  if (o.force_dt) add("force_dt", "--force-dt", "true", /*flag=*/true);
  return settings;
}

namespace {
std::atomic<double> g_output_memory_limit{4.0 * 1024 * 1024 * 1024};  // [bytes]
}  // namespace

void set_output_memory_limit(double bytes) { g_output_memory_limit = bytes; }
double output_memory_limit() { return g_output_memory_limit.load(); }

double output_memory_estimate(const DaeSystem& system, const RunSpec& run_spec, bool keep_in_memory) {
  const SimulationSettings& s = run_spec.simulation;
  const double rows = std::floor(s.t_end / output_interval_of(s)) + 2.0;                     // [rows]
  double per_row = 20.0 * static_cast<double>(system.model().body_count()) + 16.0;            // [bytes]
  if (keep_in_memory) per_row += 8.0 * static_cast<double>(timeseries_columns(system, run_spec.output_points).size());
  return rows * per_row;
}

namespace {

/// InputError when the run's output would keep more memory than the limit: the estimate, its
/// parts and what lowers it.
void require_output_memory(const DaeSystem& system, const RunSpec& run_spec, bool keep_in_memory) {
  const double limit = output_memory_limit(), estimate = output_memory_estimate(system, run_spec, keep_in_memory);
  if (!(limit > 0.0) || estimate <= limit) return;
  const SimulationSettings& s = run_spec.simulation;
  const double rows = std::floor(s.t_end / output_interval_of(s)) + 2.0;
  char text[640];
  std::snprintf(text, sizeof text,
                "the run's output would keep about %.3g GB in memory until its end (%d bodies x %.0f output rows x 20 B for "
                "the CFC filter%s), more than the limit of %.3g GB: raise --output-interval (now %g; %g or more fits), "
                "lower --t-end, or raise the limit with --max-output-memory GB (railcrash run)",
                estimate / 1e9, system.model().body_count(), rows, keep_in_memory ? ", and the timeseries kept in memory" : "",
                limit / 1e9, output_interval_of(s), output_interval_of(s) * estimate / limit);
  throw InputError(SourceLocation{system.model().file, 0}.prefix() + text);
}

}  // namespace

std::unique_ptr<Integrator> make_integrator(DaeSystem& system, const SimulationSettings& settings) {
  const CommonRunSettings run{settings.t_end, settings.static_equilibrium};
  const EulerSettings euler{settings.dt, settings.force_dt, settings.penalty, settings.max_steps, run};
  if (settings.integrator == IntegratorKind::Euler) return std::make_unique<EulerIntegrator>(system, euler);
  IdaSettings ida;
  ida.rtol = settings.rtol;
  ida.atol = settings.atol;
  ida.position_tolerance = settings.position_tolerance;
  ida.linear_ordering = settings.linear_ordering;
  ida.jacobian_kept_steps = settings.jacobian_kept_steps;
  ida.max_steps = settings.max_steps;
  ida.run = run;
  if (settings.integrator == IntegratorKind::Auto) return std::make_unique<AutoIntegrator>(system, ida, euler);
  return std::make_unique<IdaIntegrator>(system, ida);
}

RunReport run_model(const Model& model, const RunSpec& run_spec, const std::string& out_dir, const std::atomic<bool>* stop,
                    bool show_progress, bool keep_in_memory, const std::string& format, bool time_phases) {
  DaeSystem system(model);
  std::unique_ptr<ResultWriter> writer;
  std::unique_ptr<ResponseTracker> responses;
  std::vector<RunObserver*> observers;
  RunReport report;
  const SimulationSettings& simulation = run_spec.simulation;
  report.integrator = integrator_name(simulation.integrator);
  if (!out_dir.empty() || keep_in_memory) {
    require_output_memory(system, run_spec, keep_in_memory);  // before the writer starts
    observers.push_back((writer = std::make_unique<ResultWriter>(out_dir, system, run_spec, keep_in_memory, format)).get());
    writer->write_running_summary(report.integrator);
  }
  if (run_spec.responses.defined())
    observers.push_back((responses = std::make_unique<ResponseTracker>(system, run_spec.responses)).get());
  std::unique_ptr<ScenarioTracker> scenario;
  if (run_spec.scenario) observers.push_back((scenario = std::make_unique<ScenarioTracker>(system, *run_spec.scenario)).get());
  ProgressObserver observer(system, observers, simulation.t_end, show_progress);
  std::unique_ptr<Integrator> integrator;
  try {
    try {
      integrator = make_integrator(system, simulation);
    } catch (const InputError&) {
      throw;
    } catch (const std::exception& e) {  // a failed start (static settle): a failed run, with its summary
      report.outcome.message = e.what();
    }
    if (integrator) {
      integrator->time_phases(time_phases);
      try {
        report.outcome = integrator->run(simulation.t_end, output_interval_of(simulation), observer, stop);
      } catch (const std::bad_alloc&) {  // the summary says why the run ended, not "running"
        report.outcome.ok = false;
        report.outcome.t_reached = writer ? writer->last_sample_time() : 0.0;
        report.outcome.message = "out of memory (std::bad_alloc) after t = " + number_text(report.outcome.t_reached) +
                                 "; raise --output-interval or run with fewer bodies";
      }
    }
  } catch (const InputError& e) {  // found at the start (a non-finite law, joints): the summary says so too
    if (writer) {
      report.outcome.message = e.what();
      writer->write_summary(report.outcome, report.integrator);
    }
    throw;
  }
  observer.finish();
  if (!observer.non_finite_output().empty()) {  // the files end before the first non-finite output
    const double t_good = observer.last_sample_passed_on();
    const std::string held = t_good < 0.0 ? "the files hold no samples"
                                          : "the files hold the samples up to t = " + number_text(t_good);
    if (report.outcome.ok) {
      report.outcome.ok = false;
      report.outcome.message = observer.non_finite_output() + "; " + held;
      report.outcome.t_reached = std::max(t_good, 0.0);
    } else {
      report.outcome.message += "; before that, " + observer.non_finite_output() + "; " + held;
    }
  }
  if (responses) {
    report.responses = responses->result();
    report.has_responses = true;
  }
  report.outcomes = outcome_signature(report.outcome.events);
  if (writer) {
    report.summary_json =
        writer->write_summary(report.outcome, report.integrator,
                              (responses ? ",\n  \"responses\": " + responses->json() : "") +
                                  (scenario ? ",\n  \"scenario\": " + scenario->json() : "") +
                                  ",\n  \"outcomes\": " + report.outcomes.json());
    if (report.outcome.ok && !writer->failure().empty()) {  // the last write failed
      report.outcome.ok = false;
      report.outcome.message = writer->failure();
    }
    report.run_id = writer->provenance().run_id;
    report.acceleration_peaks = writer->acceleration_peaks();
    report.car_crush = writer->car_crush();
    report.filtered_accelerations = writer->filtered_accelerations();
  }
  if (keep_in_memory) {
    report.columns = timeseries_columns(system, run_spec.output_points);
    report.series = std::move(writer->columns());
  }
  return report;
}

}  // namespace railcrash
