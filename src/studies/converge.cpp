#include "railcrash/studies/converge.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "railcrash/core/whole_file.hpp"
#include "railcrash/model/model_io.hpp"
#include "railcrash/results/cfc_filter.hpp"
#include "railcrash/results/outcomes.hpp"
#include "railcrash/results/plot.hpp"
#include "railcrash/results/results.hpp"
#include "railcrash/results/run.hpp"
#include "railcrash/solver/euler_integrator.hpp"
#include "railcrash/solver/stability_limit.hpp"
#include "railcrash/solver/initial_conditions.hpp"
#include "railcrash/studies/batch.hpp"

namespace railcrash {

namespace {

/// The methods of a convergence study's runs (besides "reference"): the integrators' names.
constexpr const char* kEulerMethod = integrator_name(IntegratorKind::Euler);
constexpr const char* kIdaMethod = integrator_name(IntegratorKind::Ida);

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr long kProbeSteps = 2000;  // Euler steps timed by the plan to estimate the study's cost

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

std::string lower(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

// ---------------------------------------------------------------- quantities

const char* const kQuantityHelp =
    "max_crush, peak_anticlimber_force, peak_coupler_force, R1, R2, displacement_rms, "
    "element.NAME.OUTPUT (peak |value| of an element output), body.NAME.x|y|theta (displacement at the end), "
    "event.NAME or event.NAME:TEXT (time of the element's first event, or of its first event whose description "
    "contains TEXT) or acceleration.BODY (peak CFC-60 filtered acceleration magnitude of a body)";

std::vector<int> role_columns(const DaeSystem& system, OutputRole role) {
  std::vector<int> columns;
  for (const RoleColumn& c : columns_with_role(system, role)) columns.push_back(c.column);
  return columns;
}

ConvergeQuantity resolve_quantity(const std::string& requested, const DaeSystem& system, const ResponseSettings& responses,
                                  const std::string& length_unit, const std::string& force_unit) {
  using Kind = ConvergeQuantity::Kind;
  const Model& model = system.model();
  ConvergeQuantity q;
  q.name = requested;
  const std::string key = lower(requested);
  const auto not_applicable = [&](const std::string& why) {
    q.applicable = false;
    q.note = why;
  };
  if (key == "max_crush") {
    q.kind = Kind::MaxCrush;
    q.description = "largest crush [" + length_unit + "]";
    q.signed_peak = true;
    if (responses.crush_from_anticlimber || !responses.crush_gauges.empty()) {
      q.from_responses = true;
      q.description += responses.crush_from_anticlimber ? " (R1's measure: anticlimber horizontal deformation)"
                        : responses.total_crush      ? " (R1's measure: total shortening of the crush gauges)"
                                                     : " (R1's measure: largest shortening of a crush gauge)";
    } else {
      q.columns = role_columns(system, OutputRole::Crush);
      q.description += " (outputs with the crush role: crush_spring crush, anticlimber horizontal deformation)";
      if (q.columns.empty()) not_applicable("the model has no crush gauges and no element output with the crush role "
                                            "(crush_spring, anticlimber)");
    }
  } else if (key == "peak_anticlimber_force") {
    q.kind = Kind::PeakAnticlimberForce;
    q.description = "largest absolute horizontal force of the anticlimbers [" + force_unit + "]";
    q.columns = role_columns(system, OutputRole::ContactForce);
    if (q.columns.empty()) not_applicable("the model has no element output with the contact force role (anticlimber)");
  } else if (key == "peak_coupler_force") {
    q.kind = Kind::PeakCouplerForce;
    q.description = "largest absolute coupler face / coupling horizontal force [" + force_unit + "]";
    q.columns = role_columns(system, OutputRole::CouplerForce);
    if (q.columns.empty())
      not_applicable("the model has no element output with the coupler force role (coupler_end, coupling)");
  } else if (key == "r1") {
    q.kind = Kind::R1;
    q.name = "R1";
    q.description = "response R1 = crush / reference crush";
    if (!responses.defined())
      not_applicable("the model has no responses section");
    else if (!(responses.reference_crush > 0.0) || (responses.crush_gauges.empty() && !responses.crush_from_anticlimber))
      not_applicable("the responses section defines no crush measure with a reference crush");
  } else if (key == "r2") {
    q.kind = Kind::R2;
    q.name = "R2";
    q.description = "response R2 (vertical anticlimber force / yield force, or override)";
    if (!responses.defined())
      not_applicable("the model has no responses section");
    else if (responses.anticlimber.empty())
      not_applicable("the responses section names no anticlimber");
  } else if (key == "displacement_rms") {
    q.kind = Kind::DisplacementRms;
    q.description = "RMS of the body x/y displacement differences [" + length_unit +
                    "]; error: over the reference's largest displacement";
    if (model.body_count() == 0) not_applicable("the model has no bodies");
  } else if (key.rfind("element.", 0) == 0) {
    q.kind = Kind::ElementPeak;
    const std::string rest = requested.substr(8);
    const auto dot = rest.rfind('.');
    if (dot == std::string::npos || dot == 0 || dot + 1 == rest.size())
      throw InputError("--quantities: '" + requested + "' must be element.NAME.OUTPUT (e.g. element.anticlimber.vertical_force)");
    const std::string element = rest.substr(0, dot);
    const auto& elements = model.elements();
    const auto found = std::find_if(elements.begin(), elements.end(), [&](const auto& e) { return e->name() == element; });
    if (found == elements.end()) throw InputError("--quantities: the model has no element named '" + element + "' ('" + requested + "')");
    const auto& names = system.output_names();
    const auto it = std::find(names.begin(), names.end(), rest);
    if (it == names.end()) {
      std::string outputs;
      for (const std::string& o : (*found)->output_names()) outputs += (outputs.empty() ? "" : ", ") + o;
      throw InputError("--quantities: element '" + element + "' (" + (*found)->type() + ") has no output '" + rest.substr(dot + 1) +
                       "'; its outputs: " + (outputs.empty() ? "none" : outputs));
    }
    q.columns = {static_cast<int>(it - names.begin())};
    q.description = "largest absolute " + rest;
  } else if (key.rfind("body.", 0) == 0) {
    q.kind = Kind::BodyDisplacement;
    const std::string rest = requested.substr(5);
    const auto dot = rest.rfind('.');
    const std::string component = dot == std::string::npos ? "" : rest.substr(dot + 1);
    if (component != "x" && component != "y" && component != "theta")
      throw InputError("--quantities: '" + requested + "' must be body.NAME.x, body.NAME.y or body.NAME.theta");
    const std::optional<int> body = model.find_body(rest.substr(0, dot));
    if (!body || *body == kGround)
      throw InputError("--quantities: the model has no body named '" + rest.substr(0, dot) + "' ('" + requested + "')");
    q.body = *body;
    q.component = component == "x" ? 0 : component == "y" ? 1 : 2;
    q.description = rest + " displacement at the end [" + (q.component == 2 ? std::string("rad") : length_unit) +
                    "]; error: over the reference's largest absolute displacement";
  } else if (key.rfind("event.", 0) == 0) {
    q.kind = Kind::EventTime;
    const std::string rest = requested.substr(6);
    const auto colon = rest.find(':');
    q.event_element = rest.substr(0, colon);
    q.event_text = colon == std::string::npos ? "" : rest.substr(colon + 1);
    const auto& elements = model.elements();
    if (std::none_of(elements.begin(), elements.end(), [&](const auto& e) { return e->name() == q.event_element; }))
      throw InputError("--quantities: the model has no element named '" + q.event_element + "' ('" + requested +
                       "'); write event.NAME or event.NAME:TEXT, e.g. event.climb_limit:contact");
    q.description = "time of the first " + (q.event_text.empty() ? std::string("event") : "'" + q.event_text + "' event") +
                    " of " + q.event_element + " [s]; error: over the reference's time; a run without it: inf";
  } else if (key.rfind("acceleration.", 0) == 0) {
    q.kind = Kind::PeakAcceleration;
    const std::string name = requested.substr(13);
    const std::optional<int> body = model.find_body(name);
    if (!body || *body == kGround)
      throw InputError("--quantities: the model has no body named '" + name + "' ('" + requested + "'); write acceleration.BODY");
    q.body = *body;
    q.description = "peak CFC-60 filtered acceleration magnitude of " + name + " [g]";
  } else {
    throw InputError("--quantities: unknown quantity '" + requested + "'; use " + kQuantityHelp);
  }
  return q;
}

// ---------------------------------------------------------------- one run

std::string fmt(const char* format, double value);

/// Keeps what the quantities are made of: sample times, body displacements, output peaks.
class Recorder : public RunObserver {
 public:
  /// accelerations: an in-memory ResultWriter (no files) that filters the body accelerations
  /// as `run`'s summary does, or null.
  Recorder(const DaeSystem& system, ConvergeRun& run, ResponseTracker* responses, ResultWriter* accelerations)
      : system_(system), run_(run), responses_(responses), accelerations_(accelerations) {
    run_.peak_abs.assign(system.output_names().size(), 0.0);
    run_.peak_max.assign(system.output_names().size(), -std::numeric_limits<double>::infinity());
  }

  void sample(double t, const double* y, const double* lambda, const double* quadratures, const double* outputs) override {
    const int nq = system_.body_unknowns();
    if (start_.empty()) start_.assign(y, y + nq);
    run_.times.push_back(t);
    for (int k = 0; k < nq; ++k) run_.displacements.push_back(y[k] - start_[static_cast<std::size_t>(k)]);
    track_peaks(outputs, FreshOutputs{});
    if (responses_) responses_->sample(t, y, lambda, quadratures, outputs);
    if (accelerations_) accelerations_->sample(t, y, lambda, quadratures, outputs);
  }

  void event(const EventRecord& record, const double* y) override {
    if (responses_) responses_->event(record, y);
  }

  /// Peaks and responses from every accepted step and both sides of every event as well, as
  /// `run`'s summary takes them: a peak must not depend on the output interval (a contact's
  /// damper force peaks at the contact instant, which no output row need hit).
  void step(double t, const double* y, const double* lambda, const double* outputs, const FreshOutputs& fresh) override {
    track_peaks(outputs, fresh);
    if (responses_) responses_->step(t, y, lambda, outputs, fresh);
  }
  bool observes_steps() const override { return true; }

 private:
  void track_peaks(const double* outputs, const FreshOutputs& fresh) {
    for (std::size_t k = static_cast<std::size_t>(fresh.begin); k < fresh.end_within(run_.peak_abs.size()); ++k) {
      run_.peak_abs[k] = std::max(run_.peak_abs[k], std::abs(outputs[k]));
      run_.peak_max[k] = std::max(run_.peak_max[k], outputs[k]);
    }
  }

  const DaeSystem& system_;
  ConvergeRun& run_;
  ResponseTracker* responses_;
  ResultWriter* accelerations_;
  std::vector<double> start_;
};

class NullObserver : public RunObserver {
 public:
  void sample(double, const double*, const double*, const double*, const double*) override {}
};

std::string format_number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

/// The model of one run: the user's settings, then the run's integrator settings, through the
/// loader's override path (as run's options).
LoadedModel load_for_run(const ConvergePlan& plan, const std::string& method, double step, double rtol) {
  RunOverrides overrides;
  overrides.t_end = plan.t_end;
  overrides.output_interval = plan.output_interval;
  if (method == kEulerMethod) {
    overrides.integrator = IntegratorKind::Euler;
    overrides.dt = step;
  } else {
    overrides.integrator = IntegratorKind::Ida;
    // A model that sets atol gets it scaled with rtol, so a tighter run is tighter everywhere.
    if (plan.model_atol) overrides.atol = *plan.model_atol * rtol / plan.model_rtol;
    overrides.rtol = rtol;
  }
  return load_model(plan.model_path, plan.options.settings, option_settings(overrides, OverrideSource::ConvergeRun));
}

ConvergeRun run_one(const ConvergePlan& plan, const std::string& method, double step, double rtol,
                    const RunControl& control) {
  ConvergeRun run;
  run.method = method;
  run.step = step;
  run.rtol = rtol;
  try {
    const LoadedModel loaded = load_for_run(plan, method, step, rtol);
    const Model& model = loaded.model;
    const SimulationSettings& simulation = loaded.run_spec.simulation;
    DaeSystem system(model);
    std::unique_ptr<ResponseTracker> responses;
    if (loaded.run_spec.responses.defined()) responses = std::make_unique<ResponseTracker>(system, loaded.run_spec.responses);
    std::unique_ptr<ResultWriter> accelerations;
    if (std::any_of(plan.quantities.begin(), plan.quantities.end(),
                    [](const ConvergeQuantity& q) { return q.kind == ConvergeQuantity::Kind::PeakAcceleration; }))
      accelerations = std::make_unique<ResultWriter>("", system, loaded.run_spec);
    Recorder recorder(system, run, responses.get(), accelerations.get());
    const auto start = Clock::now();
    std::unique_ptr<Integrator> integrator = make_integrator(system, simulation);
    const RunOutcome outcome = integrator->run(simulation.t_end, output_interval_of(simulation), recorder, control.stop_flag());
    const bool timed_out = control.timed_out();
    run.wall_seconds = seconds_since(start);
    run.ok = outcome.ok;
    run.message = outcome.message;
    if (timed_out && !outcome.ok)
      run.message = run_limit_message(plan.options.run_time_limit, outcome.t_reached);
    run.stats = outcome.stats;
    run.events = outcome.events;
    if (accelerations) {
      const double g = standard_gravity(model);
      for (const FilteredAccelerations& f : accelerations->filtered_accelerations())
        run.peak_acceleration.push_back(f.filtered ? f.peaks.magnitude / g : kNaN);
    }
    if (responses) {
      run.has_responses = true;
      run.responses = responses->result();
    }
  } catch (const std::exception& e) {
    run.ok = false;
    run.message = e.what();
  }
  return run;
}

// ---------------------------------------------------------------- analysis

double crush_from_responses(const Responses& r, const ResponseSettings& settings) {
  if (settings.crush_from_anticlimber) return r.max_anticlimber_crush;
  double crush = 0.0;
  for (double c : r.max_crush) crush = settings.total_crush ? crush + c : std::max(crush, c);
  return crush;
}

/// Value of a scalar quantity for a finished run (displacement_rms is done against the reference).
double scalar_value(const ConvergeQuantity& q, const ConvergeRun& run, const ResponseSettings& settings, int body_count) {
  using Kind = ConvergeQuantity::Kind;
  if (!q.applicable || !run.ok) return kNaN;
  switch (q.kind) {
    case Kind::MaxCrush:
      if (q.from_responses) return crush_from_responses(run.responses, settings);
      [[fallthrough]];
    case Kind::PeakAnticlimberForce:
    case Kind::PeakCouplerForce:
    case Kind::ElementPeak: {
      double peak = -std::numeric_limits<double>::infinity();
      for (int c : q.columns) {
        const auto k = static_cast<std::size_t>(c);
        peak = std::max(peak, q.signed_peak ? run.peak_max[k] : run.peak_abs[k]);
      }
      return peak;
    }
    case Kind::R1: return run.responses.r1;
    case Kind::R2: return run.responses.r2;
    case Kind::BodyDisplacement: {
      if (run.times.empty()) return kNaN;
      const std::size_t last = run.times.size() - 1;
      return run.displacements[last * 3 * static_cast<std::size_t>(body_count) + 3 * static_cast<std::size_t>(q.body) +
                               static_cast<std::size_t>(q.component)];
    }
    case Kind::DisplacementRms: return kNaN;
    case Kind::EventTime:
      for (const EventRecord& e : run.events)
        if (e.element == q.event_element && e.what.find(q.event_text) != std::string::npos) return e.t;
      return kNaN;
    case Kind::PeakAcceleration:
      return static_cast<std::size_t>(q.body) < run.peak_acceleration.size() ? run.peak_acceleration[static_cast<std::size_t>(q.body)]
                                                                            : kNaN;
  }
  return kNaN;
}

/// RMS over the reference's sample times and all bodies of the x/y displacement difference,
/// the run's history interpolated linearly in time.
double displacement_rms(const ConvergeRun& run, const ConvergeRun& reference, int body_count) {
  if (!run.ok || run.times.empty()) return kNaN;
  const auto n = static_cast<std::size_t>(3 * body_count);
  double sum = 0.0;
  long count = 0;
  for (std::size_t i = 0; i < reference.times.size(); ++i) {
    const double t = reference.times[i];
    const auto after = std::lower_bound(run.times.begin(), run.times.end(), t);
    std::size_t hi = static_cast<std::size_t>(after - run.times.begin());
    if (hi == run.times.size()) {
      if (t > run.times.back() * (1.0 + 1e-9) + 1e-300) continue;  // beyond the run's end
      hi = run.times.size() - 1;
    }
    const std::size_t lo = hi == 0 ? 0 : hi - 1;
    const double span = run.times[hi] - run.times[lo];
    const double w = span > 0.0 ? std::clamp((t - run.times[lo]) / span, 0.0, 1.0) : 1.0;
    for (int b = 0; b < body_count; ++b)
      for (int c = 0; c < 2; ++c) {
        const std::size_t k = 3 * static_cast<std::size_t>(b) + static_cast<std::size_t>(c);
        const double value = (1.0 - w) * run.displacements[lo * n + k] + w * run.displacements[hi * n + k];
        const double d = value - reference.displacements[i * n + k];
        sum += d * d;
        ++count;
      }
  }
  return count > 0 ? std::sqrt(sum / static_cast<double>(count)) : kNaN;
}

double largest_displacement(const ConvergeRun& reference, int body_count, int body, int component) {
  const auto n = static_cast<std::size_t>(3 * body_count);
  double largest = 0.0;
  for (std::size_t i = 0; i < reference.times.size(); ++i)
    for (int b = 0; b < body_count; ++b)
      for (int c = 0; c < 3; ++c) {
        const bool wanted = body >= 0 ? (b == body && c == component) : c < 2;
        if (wanted) largest = std::max(largest, std::abs(reference.displacements[i * n + 3 * static_cast<std::size_t>(b) +
                                                                                  static_cast<std::size_t>(c)]));
      }
  return largest;
}

void evaluate(ConvergeRun& run, const ConvergeRun& reference, const std::vector<ConvergeQuantity>& quantities,
              const ResponseSettings& settings, int body_count) {
  using Kind = ConvergeQuantity::Kind;
  run.values.assign(quantities.size(), kNaN);
  run.errors.assign(quantities.size(), kNaN);
  for (std::size_t k = 0; k < quantities.size(); ++k) {
    const ConvergeQuantity& q = quantities[k];
    if (!q.applicable) continue;
    if (q.kind == Kind::DisplacementRms) {
      if (!reference.ok) continue;
      run.values[k] = displacement_rms(run, reference, body_count);
      const double scale = largest_displacement(reference, body_count, -1, 0);
      run.errors[k] = scale > 0.0 ? run.values[k] / scale : kNaN;
      continue;
    }
    run.values[k] = scalar_value(q, run, settings, body_count);
    const double ref = scalar_value(q, reference, settings, body_count);
    const double scale =
        q.kind == Kind::BodyDisplacement ? largest_displacement(reference, body_count, q.body, q.component) : std::abs(ref);
    if (std::isfinite(run.values[k]) && std::isfinite(ref))
      run.errors[k] = scale > 0.0 ? std::abs(run.values[k] - ref) / scale : (run.values[k] == ref ? 0.0 : kNaN);
    else if (q.kind == Kind::EventTime && run.ok && std::isfinite(ref))
      run.errors[k] = std::numeric_limits<double>::infinity();  // the reference's event did not happen in this run
  }
}

}  // namespace

/// Wall time at which a method's runs reach a relative error level (see the header). A run
/// counts only when it and every tighter run of the method (smaller dt or rtol) meet the level:
/// an error that meets it by luck at a loose setting and misses it again at a tighter one
/// (events that fire elsewhere, a bifurcation) is not a setting anyone could rely on.
TimeAtLevel time_at_level(const std::vector<ConvergeRun>& runs, std::size_t quantity, double level) {
  struct Point {
    double setting, seconds, error;  // dt or rtol, wall time, relative error
  };
  std::vector<Point> points;  // usable runs, loosest setting first
  for (const ConvergeRun& r : runs)
    if (r.ok && r.wall_seconds > 0.0 && std::isfinite(r.errors[quantity]))
      points.push_back({r.method == kEulerMethod ? r.step : r.rtol, r.wall_seconds, r.errors[quantity]});
  if (points.empty()) return {kNaN, "no runs"};
  std::sort(points.begin(), points.end(), [](const Point& a, const Point& b) { return a.setting > b.setting; });
  std::size_t first_reliable = points.size();  // the loosest run from which on every tighter one meets the level
  while (first_reliable > 0 && points[first_reliable - 1].error <= level) --first_reliable;
  if (first_reliable == 0) return {points[0].seconds, "<="};
  if (first_reliable < points.size()) {
    const Point& above = points[first_reliable - 1];  // misses the level
    const Point& below = points[first_reliable];      // meets it, as do all tighter runs
    if (!(below.error > 0.0)) return {below.seconds, "<="};
    const double lt0 = std::log(above.seconds), lt1 = std::log(below.seconds);
    const double le0 = std::log(above.error), le1 = std::log(below.error);
    return {std::exp(lt0 + (std::log(level) - le0) * (lt1 - lt0) / (le1 - le0)), "interpolated"};
  }
  std::vector<double> times, errors;
  for (const Point& p : points)
    if (p.error > 0.0) times.push_back(p.seconds), errors.push_back(p.error);
  const ConvergeFit fit = log_log_slope(times, errors);
  if (fit.points < 2 || !(fit.slope < 0.0)) return {kNaN, "not reached"};
  // Line through the centroid of the points with the fitted slope.
  double mean_t = 0.0, mean_e = 0.0;
  for (std::size_t k = 0; k < times.size(); ++k) mean_t += std::log(times[k]), mean_e += std::log(errors[k]);
  mean_t /= static_cast<double>(times.size());
  mean_e /= static_cast<double>(times.size());
  return {std::exp(mean_t + (std::log(level) - mean_e) / fit.slope), "extrapolated"};
}

namespace {

std::vector<double> column(const std::vector<ConvergeRun>& runs, const std::function<double(const ConvergeRun&)>& get) {
  std::vector<double> out;
  for (const ConvergeRun& r : runs) out.push_back(r.ok ? get(r) : kNaN);
  return out;
}

void analyse(ConvergeResult& result, const ConvergePlan& plan, const ResponseSettings& settings, int body_count) {
  evaluate(result.reference, result.reference, result.quantities, settings, body_count);
  for (auto* runs : {&result.euler, &result.ida})
    for (ConvergeRun& r : *runs) evaluate(r, result.reference, result.quantities, settings, body_count);
  for (std::size_t q = 0; q < result.quantities.size(); ++q) {
    const auto errors = [&](const ConvergeRun& r) { return r.errors[q]; };
    const std::vector<double> euler_errors = column(result.euler, errors), ida_errors = column(result.ida, errors);
    result.euler_order.push_back(log_log_slope(column(result.euler, [](const ConvergeRun& r) { return r.step; }), euler_errors));
    result.euler_time_slope.push_back(
        log_log_slope(column(result.euler, [](const ConvergeRun& r) { return r.wall_seconds; }), euler_errors));
    result.ida_rtol_slope.push_back(log_log_slope(column(result.ida, [](const ConvergeRun& r) { return r.rtol; }), ida_errors));
    result.ida_time_slope.push_back(
        log_log_slope(column(result.ida, [](const ConvergeRun& r) { return r.wall_seconds; }), ida_errors));
  }
  if (result.headline >= 0)
    for (double level : plan.options.levels) {
      ConvergeLevel l;
      l.level = level;
      const auto q = static_cast<std::size_t>(result.headline);
      const TimeAtLevel euler = time_at_level(result.euler, q, level), ida = time_at_level(result.ida, q, level);
      l.euler_seconds = euler.seconds;
      l.euler_how = euler.how;
      l.ida_seconds = ida.seconds;
      l.ida_how = ida.how;
      result.levels.push_back(l);
    }
}

// ---------------------------------------------------------------- text

std::string fmt(const char* format, double value) {
  if (!std::isfinite(value)) return "–";
  char text[64];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

std::string slope_text(const ConvergeFit& fit) {
  if (fit.points < 2) return "–";
  return fmt("%.2f", fit.slope) + " (" + std::to_string(fit.points) + ")";
}

std::string level_time_text(double seconds, const std::string& how) {
  if (how == "interpolated") return fmt("%.3g", seconds);
  if (how == "<=") return "<= " + fmt("%.3g", seconds) + " (cheapest run already below)";
  if (how == "extrapolated") return fmt("%.3g", seconds) + " (extrapolated)";
  return how;
}

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' ? ' ' : c);
  return out + "\"";
}

}  // namespace

std::vector<std::string> default_quantities() {
  return {"max_crush", "peak_anticlimber_force", "peak_coupler_force", "R1", "R2", "displacement_rms"};
}

ConvergeFit log_log_slope(const std::vector<double>& x, const std::vector<double>& y) {
  ConvergeFit fit;
  fit.slope = kNaN;
  std::vector<double> lx, ly;
  for (std::size_t k = 0; k < std::min(x.size(), y.size()); ++k)
    if (std::isfinite(x[k]) && std::isfinite(y[k]) && x[k] > 0.0 && y[k] > 0.0) {
      lx.push_back(std::log(x[k]));
      ly.push_back(std::log(y[k]));
    }
  fit.points = static_cast<int>(lx.size());
  if (lx.size() < 2) return fit;
  double mx = 0.0, my = 0.0;
  for (std::size_t k = 0; k < lx.size(); ++k) mx += lx[k], my += ly[k];
  mx /= static_cast<double>(lx.size());
  my /= static_cast<double>(lx.size());
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t k = 0; k < lx.size(); ++k) {
    sxy += (lx[k] - mx) * (ly[k] - my);
    sxx += (lx[k] - mx) * (lx[k] - mx);
  }
  if (sxx > 0.0) fit.slope = sxy / sxx;
  return fit;
}

ConvergePlan plan_convergence(const std::string& model_path, const ConvergeOptions& options) {
  if (options.euler_runs < 0 || options.euler_runs > 30) throw InputError("--euler-steps must be between 0 and 30");
  if (!(options.euler_safety > 0.0 && options.euler_safety < 1.0))
    throw InputError("--euler-safety must be between 0 and 1 (e.g. 0.8)");
  if (options.euler_first_step < 0.0 || !std::isfinite(options.euler_first_step))
    throw InputError("--euler-dt must be a positive step");
  if (const std::string problem = rtol_problem(options.reference_rtol, "--reference-rtol", "1e-9"); !problem.empty()) throw InputError(problem);
  for (double r : options.rtols)
    if (const std::string problem = rtol_problem(r, "--rtols: every tolerance"); !problem.empty()) throw InputError(problem);
  for (double r : options.rtols)
    if (r <= options.reference_rtol)
      throw InputError("--rtols: " + format_number(r) + " is not looser than the reference tolerance " +
                       format_number(options.reference_rtol) + " (the reference must be the most accurate run)");
  for (double l : options.levels)
    if (!(l > 0.0)) throw InputError("--levels: error levels must be positive (e.g. 0.01,0.001)");
  if (options.jobs < 1) throw InputError("--jobs must be at least 1");
  if (options.run_time_limit < 0.0 || !std::isfinite(options.run_time_limit))
    throw InputError("--run-timeout must be 0 (no limit) or a positive number of seconds");

  ConvergePlan plan;
  plan.model_path = model_path;
  plan.options = options;
  RunOverrides overrides;  // converge's --t-end and --output-interval, through --set's path as in run
  overrides.t_end = options.t_end;
  overrides.output_interval = options.output_interval;
  const LoadedModel loaded = load_model(model_path, options.settings, option_settings(overrides));
  const Model& model = loaded.model;
  const SimulationSettings& simulation = loaded.run_spec.simulation;
  plan.t_end = simulation.t_end;
  plan.output_interval = output_interval_of(simulation);
  plan.model_rtol = simulation.rtol;
  if (const std::optional<double> atol = simulation.atol) plan.model_atol = *atol / file_length_unit(model);
  plan.model_name = model.name;
  const bool si = model.units == UnitSystem::SI;
  plan.length_unit = si ? "m" : "in";
  plan.force_unit = si ? "N" : "lbf";

  DaeSystem system(model);
  for (const std::string& name : options.quantities.empty() ? default_quantities() : options.quantities)
    plan.quantities.push_back(resolve_quantity(name, system, loaded.run_spec.responses, plan.length_unit, plan.force_unit));
  for (std::size_t k = 0; k < plan.quantities.size(); ++k) {
    const ConvergeQuantity& q = plan.quantities[k];
    const bool named = !options.headline.empty() && lower(q.name) == lower(options.headline);
    if (named && !q.applicable) throw InputError("--headline: " + q.name + " does not apply to this model: " + q.note);
    if (named || (options.headline.empty() && plan.headline < 0 && q.applicable)) plan.headline = static_cast<int>(k);
  }
  if (!options.headline.empty() && plan.headline < 0)
    throw InputError("--headline: '" + options.headline + "' is not one of the study's quantities (--quantities)");
  for (const ConvergeQuantity& q : plan.quantities)
    if (q.kind == ConvergeQuantity::Kind::PeakAcceleration && !cfc::adequately_sampled(60.0, plan.output_interval))
      throw InputError("--quantities: " + q.name + " is filtered at CFC 60, which needs at least 600 output rows per second; "
                       "the study's output interval is " + format_number(plan.output_interval) +
                       " s: give --output-interval 1e-3 or less");

  if (options.euler_runs == 0) return plan;
  // Euler's first step: a safety factor times the stability limit of the elements, as a whole
  // fraction of the output interval. The penalty joints stiffen as the step shrinks
  // (k ~ 1/dt^2), so the limit with them scales with the step: the step is accepted when it
  // is below the limit computed with its own penalties (the integrator's own test), and
  // otherwise lowered to safety x that limit.
  const auto commensurate = [&](double dt) {
    return dt < plan.output_interval ? plan.output_interval / std::ceil(plan.output_interval / dt * (1.0 - 1e-12)) : dt;
  };
  // The model's penalty settings, t_end and static settle (max_steps: Euler's default).
  const auto euler_settings = [&simulation](double dt, bool force_dt) {
    EulerSettings settings;
    settings.dt = dt;
    settings.force_dt = force_dt;
    settings.penalty = simulation.penalty;
    settings.run = {simulation.t_end, simulation.static_equilibrium};
    return settings;
  };
  double dt0 = options.euler_first_step;
  std::unique_ptr<EulerIntegrator> euler;
  if (dt0 > 0.0) {
    euler = std::make_unique<EulerIntegrator>(system, euler_settings(dt0, false));
  } else {
    // The elements' own limit at the start (what `railcrash check` prints), then the penalties.
    std::vector<double> y0 = system.initial_state();
    std::vector<EventRecord> start_events;
    prepare_start(system, y0, start_events, simulation.static_equilibrium);
    plan.element_stability_limit = explicit_stability_limit(system, y0, nullptr);
    if (!std::isfinite(plan.element_stability_limit))
      throw InputError("the model's elements give Euler no stability limit (no stiffness); give a first step with --euler-dt");
    dt0 = commensurate(options.euler_safety * plan.element_stability_limit);
    for (int pass = 0; pass < 10; ++pass) {
      euler = std::make_unique<EulerIntegrator>(system, euler_settings(dt0, true));
      if (dt0 <= euler->stability_limit()) break;
      dt0 = commensurate(options.euler_safety * euler->stability_limit());
    }
    if (dt0 > euler->stability_limit())
      throw InputError("no stable Euler step found below " + format_number(dt0) + " s; give one with --euler-dt");
  }
  plan.stability_limit = euler->stability_limit();
  for (int k = 0; k < options.euler_runs; ++k) plan.euler_steps.push_back(dt0 / std::pow(2.0, k));
  // Every Euler run must be one the integrator takes: a step that needs more than max_steps
  // steps is refused now, not when its run comes (after the others have run).
  const double smallest_step = plan.euler_steps.back();
  const double steps_needed = std::ceil(plan.t_end / smallest_step - 1e-9);  // [steps]
  if (!(steps_needed <= static_cast<double>(simulation.max_steps)))
    throw InputError(model_path + ": --euler-steps " + std::to_string(options.euler_runs) + " from dt " + format_number(dt0) +
                     " s goes down to " + fmt("%.4g", smallest_step) + " s, which needs " + fmt("%.4g", steps_needed) +
                     " steps to reach t_end = " + format_number(plan.t_end) + ", more than max_steps " +
                     std::to_string(simulation.max_steps) + "; use fewer --euler-steps, a larger --euler-dt or a shorter --t-end");
  // Time a short run at dt_0 for the cost per step (the same for every step size).
  NullObserver none;
  const double probe_end = std::min(plan.t_end, static_cast<double>(kProbeSteps) * dt0);
  const RunOutcome probe = euler->run(probe_end, probe_end, none);
  plan.euler_seconds_per_step = probe.stats.steps > 0 ? probe.stats.wall_seconds / static_cast<double>(probe.stats.steps) : 0.0;
  for (double dt : plan.euler_steps) plan.euler_estimate_seconds += std::ceil(plan.t_end / dt) * plan.euler_seconds_per_step;
  return plan;
}

ConvergeResult run_convergence(const ConvergePlan& plan, const std::function<void(const ConvergeRun&)>& on_run,
                               const std::atomic<bool>* stop) {
  const auto start = Clock::now();
  ConvergeResult result;
  result.model_path = plan.model_path;
  result.model_name = plan.model_name;
  result.length_unit = plan.length_unit;
  result.force_unit = plan.force_unit;
  result.t_end = plan.t_end;
  result.output_interval = plan.output_interval;
  result.stability_limit = plan.stability_limit;
  result.element_stability_limit = plan.element_stability_limit;
  result.quantities = plan.quantities;
  result.headline = plan.headline;

  struct Job {
    std::string method;
    double step = 0.0, rtol = 0.0;
  };
  std::vector<Job> jobs{{"reference", 0.0, plan.options.reference_rtol}};
  for (double dt : plan.euler_steps) jobs.push_back({kEulerMethod, dt, 0.0});
  for (double rtol : plan.options.rtols) jobs.push_back({kIdaMethod, 0.0, rtol});
  std::vector<ConvergeRun> runs(jobs.size());
  BatchOptions batch;
  batch.jobs = plan.options.jobs;
  batch.run_time_limit = plan.options.run_time_limit;
  batch.stop = stop;
  const std::vector<BatchRunState> states = run_batch(
      jobs.size(), [&](std::size_t k, const RunControl& control) {
        runs[k] = run_one(plan, jobs[k].method, jobs[k].step, jobs[k].rtol, control);
      },
      batch, [&](std::size_t k, BatchRunState) {
        if (on_run) on_run(runs[k]);
      });
  result.runs_total = jobs.size();
  result.runs_finished = finished_runs(states);
  result.interrupted = result.runs_finished < result.runs_total;
  for (std::size_t k = 0; k < jobs.size(); ++k) {
    if (states[k] == BatchRunState::interrupted) {
      runs[k].ok = false;
      runs[k].message = "interrupted (SIGINT/SIGTERM): " + runs[k].message;
    } else if (states[k] == BatchRunState::not_started) {
      runs[k].method = jobs[k].method;
      runs[k].step = jobs[k].step;
      runs[k].rtol = jobs[k].rtol;
      runs[k].message = "not run (interrupted)";
    }
  }
  result.jobs = std::max(1, std::min<int>(plan.options.jobs, static_cast<int>(jobs.size())));

  result.reference = runs[0];
  // A reference that fails (tight tolerances can stall IDA at an event) is retried ten times
  // looser while that stays tighter than every run it is the reference for.
  const double loosest_allowed =
      plan.options.rtols.empty() ? 1e-7 : 0.1 * *std::min_element(plan.options.rtols.begin(), plan.options.rtols.end());
  while (!result.reference.ok && !(stop && stop->load()) && 10.0 * result.reference.rtol <= loosest_allowed * (1.0 + 1e-9)) {
    result.reference_note += "reference at rtol " + fmt("%.0e", result.reference.rtol) + " failed (" + result.reference.message +
                             "); ";
    const double looser = 10.0 * result.reference.rtol;
    BatchOptions single = batch;
    single.jobs = 1;
    run_batch(1, [&](std::size_t, const RunControl& control) { result.reference = run_one(plan, "reference", 0.0, looser, control); },
              single);
    if (on_run) on_run(result.reference);
  }
  if (!result.reference_note.empty())
    result.reference_note += result.reference.ok ? "used rtol " + fmt("%.0e", result.reference.rtol) + " instead."
                                                 : "no looser reference tried (it must stay 10x tighter than every run).";
  for (std::size_t k = 1; k < runs.size(); ++k) (runs[k].method == kEulerMethod ? result.euler : result.ida).push_back(runs[k]);
  // The model's response settings and body count, for the analysis.
  const LoadedModel loaded = load_model(plan.model_path, plan.options.settings);
  analyse(result, plan, loaded.run_spec.responses, loaded.model.body_count());
  result.total_seconds = seconds_since(start);
  return result;
}

std::string convergence_markdown(const ConvergeResult& r) {
  std::ostringstream md;
  const std::size_t nq = r.quantities.size();
  if (r.interrupted)
    md << "**Interrupted after " << r.runs_finished << " of " << r.runs_total
       << " runs** (SIGINT/SIGTERM): the runs not finished are marked failed and left out of the analysis.\n\n";
  md << "Model `" << r.model_path << "` (" << r.model_name << "), t_end " << r.t_end << " s, output every "
     << r.output_interval << " s; " << r.euler.size() << " Euler and " << r.ida.size() << " IDA runs against an IDA reference at rtol "
     << r.reference.rtol << "; " << r.jobs << " job" << (r.jobs > 1 ? "s (wall times under parallel load)" : "") << "; "
     << fmt("%.3g", r.total_seconds) << " s in all.";
  // Either limit may be unknown (with --euler-dt the elements' limit is not computed).
  if (r.element_stability_limit > 0.0 && r.stability_limit > 0.0)
    md << " Euler stability limit of the elements " << fmt("%.4g", r.element_stability_limit) << " s, with the penalty joints at the first step "
       << fmt("%.4g", r.stability_limit) << " s.";
  else if (r.element_stability_limit > 0.0)
    md << " Euler stability limit of the elements " << fmt("%.4g", r.element_stability_limit) << " s.";
  else if (r.stability_limit > 0.0)
    md << " Euler stability limit with the penalty joints at the first step " << fmt("%.4g", r.stability_limit) << " s.";
  md << "\n\n";
  if (!r.reference_note.empty()) md << "Reference: " << r.reference_note << "\n\n";
  if (!r.reference.ok) md << "**The reference run failed** (" << r.reference.message << "): no errors can be computed.\n\n";

  const auto cell = [](std::string text) {  // a '|' would end the table cell
    for (std::size_t at = text.find('|'); at != std::string::npos; at = text.find('|', at + 2)) text.insert(at, "\\");
    return text;
  };
  md << "| quantity | meaning | reference value |\n|---|---|---|\n";
  for (std::size_t q = 0; q < nq; ++q) {
    const ConvergeQuantity& quantity = r.quantities[q];
    md << "| " << cell(quantity.name) << (static_cast<int>(q) == r.headline ? " (headline)" : "") << " | "
       << cell(quantity.description) << " | "
       << (!quantity.applicable                                            ? cell("not applicable: " + quantity.note)
           : quantity.kind == ConvergeQuantity::Kind::DisplacementRms ? std::string("–")
                                                                       : fmt("%.6g", r.reference.values[q]))
       << " |\n";
  }

  md << "\nRelative errors against the reference:\n\n| method | dt [s] / rtol | status | wall [s] | steps | residual evals | "
        "Jacobian evals | events |";
  for (const ConvergeQuantity& q : r.quantities)
    if (q.applicable) md << " " << q.name << " |";
  md << "\n|---|---|---|---|---|---|---|---|";
  for (const ConvergeQuantity& q : r.quantities)
    if (q.applicable) md << "---|";
  md << "\n";
  const auto row = [&](const ConvergeRun& run) {
    md << "| " << run.method << " | " << (run.method == kEulerMethod ? fmt("%.4g", run.step) : fmt("%.0e", run.rtol)) << " | "
       << (run.ok ? "ok" : "failed") << " | " << fmt("%.3g", run.wall_seconds) << " | " << run.stats.steps << " | "
       << run.stats.residual_evaluations << " | " << run.stats.jacobian_evaluations << " | " << run.stats.events << " |";
    for (std::size_t q = 0; q < nq; ++q)
      if (r.quantities[q].applicable) md << " " << (run.errors.empty() ? "–" : fmt("%.2e", run.errors[q])) << " |";
    md << "\n";
  };
  row(r.reference);
  for (const ConvergeRun& run : r.euler) row(run);
  for (const ConvergeRun& run : r.ida) row(run);
  for (const auto* runs : {&r.euler, &r.ida})
    for (const ConvergeRun& run : *runs)
      if (!run.ok) md << "\n" << run.method << " " << (run.method == kEulerMethod ? "dt " + fmt("%.4g", run.step) : "rtol " + fmt("%.0e", run.rtol))
                      << " failed: " << run.message << "\n";

  md << "\nObserved orders (least-squares slope of log error, number of runs in the fit):\n\n"
        "| quantity | Euler: vs log dt (order) | Euler: vs log wall time | IDA: vs log rtol | IDA: vs log wall time |\n"
        "|---|---|---|---|---|\n";
  for (std::size_t q = 0; q < nq; ++q)
    if (r.quantities[q].applicable)
      md << "| " << r.quantities[q].name << " | " << slope_text(r.euler_order[q]) << " | " << slope_text(r.euler_time_slope[q])
         << " | " << slope_text(r.ida_rtol_slope[q]) << " | " << slope_text(r.ida_time_slope[q]) << " |\n";

  if (r.headline >= 0 && !r.levels.empty()) {
    md << "\nWall time to reach a relative error in " << r.quantities[static_cast<std::size_t>(r.headline)].name
       << " (log-log interpolation between runs):\n\n| error level | Euler [s] | IDA [s] | Euler / IDA |\n|---|---|---|---|\n";
    for (const ConvergeLevel& l : r.levels) {
      std::string ratio = "–";
      if (std::isfinite(l.euler_seconds) && std::isfinite(l.ida_seconds) && l.ida_seconds > 0.0) {
        ratio = fmt("%.3g", l.euler_seconds / l.ida_seconds);
        const bool euler_bound = l.euler_how == "<=", ida_bound = l.ida_how == "<=";
        if (euler_bound && !ida_bound) ratio = "<= " + ratio;
        else if (ida_bound && !euler_bound) ratio = ">= " + ratio;
        else if (euler_bound && ida_bound) ratio += " (both bounds only)";
        if (l.euler_how == "extrapolated" || l.ida_how == "extrapolated") ratio += " (extrapolated)";
      }
      md << "| " << fmt("%.3g", 100.0 * l.level) << " % | " << level_time_text(l.euler_seconds, l.euler_how) << " | "
         << level_time_text(l.ida_seconds, l.ida_how) << " | " << ratio << " |\n";
    }
  } else if (r.headline < 0) {
    md << "\nNo applicable quantity: no cost comparison.\n";
  }
  return md.str();
}

std::string write_convergence(const ConvergeResult& r, const std::string& directory) {
  std::error_code error;
  std::filesystem::create_directories(directory, error);
  if (error) throw InputError("cannot create the output folder '" + directory + "': " + error.message());
  std::ostringstream csv;
  csv << "method,step,rtol,status,wall_s,steps,residual_evaluations,jacobian_evaluations,events";
  for (const ConvergeQuantity& q : r.quantities) csv << "," << csv_field(q.name) << "," << csv_field(q.name + "_error");
  csv << ",message,outcomes,branch,integrator_used,euler_from_t\n";
  const auto number = [](double v) { return std::isfinite(v) ? format_number(v) : std::string(); };
  const OutcomeSignature reference_outcomes = outcome_signature(r.reference.events);
  const auto row = [&](const ConvergeRun& run) {
    csv << run.method << "," << (run.method == kEulerMethod ? number(run.step) : "") << "," << (run.method == kEulerMethod ? "" : number(run.rtol))
        << "," << (run.ok ? "ok" : "failed") << "," << number(run.wall_seconds) << "," << run.stats.steps << ","
        << run.stats.residual_evaluations << "," << run.stats.jacobian_evaluations << "," << run.stats.events;
    for (std::size_t q = 0; q < r.quantities.size(); ++q)
      csv << "," << (run.values.empty() ? "" : number(run.values[q])) << "," << (run.errors.empty() ? "" : number(run.errors[q]));
    // The run's discrete outcome (issue 40), and whether it is the reference's ("same") or not.
    const OutcomeSignature outcomes = outcome_signature(run.events);
    csv << "," << csv_field(run.message) << "," << csv_field(run.ok ? outcomes.text() : "") << ","
        << (!run.ok || !r.reference.ok ? "" : &run == &r.reference ? "reference" : same_branch(outcomes, reference_outcomes) ? "same" : "changed");
    // The method that ran (the study names ida or euler for each run; an IDA run is never handed over).
    IntegratorUsed used;
    used.method = run.method == kEulerMethod ? kEulerMethod : ida_or_auto_method(run.stats);
    if (run.stats.handed_over_at >= 0.0) used.euler_from_t = run.stats.handed_over_at;
    csv << "," << used.method << "," << used.euler_from_t_text() << "\n";
  };
  row(r.reference);
  for (const ConvergeRun& run : r.euler) row(run);
  for (const ConvergeRun& run : r.ida) row(run);
  write_whole_file(directory + "/converge.csv", csv.str());

  plot::Figure figure;
  figure.log_x = figure.log_y = true;
  figure.x_label = "wall time [s]";
  if (r.headline >= 0) {
    const auto q = static_cast<std::size_t>(r.headline);
    figure.title = "Error versus cost: " + r.model_name;
    figure.y_label = "relative error in " + r.quantities[q].name;
    double low = std::numeric_limits<double>::infinity(), high = 0.0;
    for (const auto& [label, runs] : {std::pair<const char*, const std::vector<ConvergeRun>*>{"explicit Euler (dt halved)", &r.euler},
                                      {"IDA (rtol)", &r.ida}}) {
      plot::Series series;
      series.label = label;
      series.markers = true;
      for (const ConvergeRun& run : *runs)
        if (run.ok && !run.errors.empty()) {
          series.x.push_back(run.wall_seconds);
          series.y.push_back(run.errors[q]);
          low = std::min(low, run.wall_seconds);
          high = std::max(high, run.wall_seconds);
        }
      figure.series.push_back(series);
    }
    for (const ConvergeLevel& l : r.levels) {
      if (!(high > 0.0)) break;
      plot::Series level;
      level.label = fmt("%.3g", 100.0 * l.level) + " % level";
      level.dashed = true;
      level.x = {low, high};
      level.y = {l.level, l.level};
      figure.series.push_back(level);
    }
  } else {
    figure.title = "Error versus cost: no applicable quantity";
  }
  plot::write_svg(figure, directory + "/converge.svg");
  const std::string md = convergence_markdown(r);
  write_whole_file(directory + "/converge.md", md);
  return md;
}

}  // namespace railcrash
