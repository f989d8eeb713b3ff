// The public interface (api.hpp) over the loader and run_model. A Model keeps the YAML text
// and the settings, not the loaded model and its run settings (LoadedModel): every run loads
// its own pair (as the sensitivity study does), so runs of one Model from several threads
// never share anything (element modes and histories live in each run's ElementStates, model.hpp).
#include "railcrash/api.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "railcrash/core/json_text.hpp"
#include "railcrash/model/model_io.hpp"
#include "railcrash/results/accuracy_check.hpp"
#include "railcrash/results/results.hpp"
#include "railcrash/results/run.hpp"
#include "railcrash/solver/dae_system.hpp"

#ifndef RAILCRASH_VERSION
#error "RAILCRASH_VERSION must be defined by the build"
#endif

namespace railcrash::api {

const char* version() { return RAILCRASH_VERSION; }

struct Model::Impl {
  std::string text, path, source;  // source: the name used in messages
  std::vector<std::string> settings;
  std::string name, units;
  std::vector<std::string> bodies, columns;
  std::vector<std::pair<std::string, std::string>> elements;
  double t_end = 0.0;
};

struct Access {
  static const Model::Impl& impl(const Model& model) { return *model.impl_; }

  /// Loads (so every problem shows now) and keeps what the accessors report.
  static Model make(std::string text, std::string path, std::string source, std::vector<std::string> settings) {
    const LoadedModel file = load_model_text(text, source, settings);
    const railcrash::Model& loaded = file.model;
    auto impl = std::make_shared<Model::Impl>();
    impl->text = std::move(text);
    impl->path = std::move(path);
    impl->source = std::move(source);
    impl->settings = std::move(settings);
    impl->name = loaded.name;
    impl->units = unit_system_name(loaded.units);
    for (const Body& b : loaded.bodies()) impl->bodies.push_back(b.name);
    for (const auto& e : loaded.elements()) impl->elements.emplace_back(e->name(), e->type());
    impl->t_end = file.run_spec.simulation.t_end;
    impl->columns = timeseries_columns(DaeSystem(loaded), file.run_spec.output_points);
    return Model(std::move(impl));
  }
};

Model::Model(std::shared_ptr<const Impl> impl) : impl_(std::move(impl)) {}

Model Model::load(const std::string& path, const std::vector<std::string>& settings) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open the model file (check the path)");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return Access::make(buffer.str(), path, path, settings);
}

Model Model::from_yaml(const std::string& text, const std::string& source, const std::vector<std::string>& settings) {
  return Access::make(text, "", source, settings);
}

Model Model::with(const std::vector<std::string>& settings) const {
  std::vector<std::string> all = impl_->settings;
  all.insert(all.end(), settings.begin(), settings.end());
  return Access::make(impl_->text, impl_->path, impl_->source, std::move(all));
}

const std::string& Model::name() const { return impl_->name; }
const std::string& Model::path() const { return impl_->path; }
const std::string& Model::yaml() const { return impl_->text; }
const std::vector<std::string>& Model::settings() const { return impl_->settings; }
const std::string& Model::units() const { return impl_->units; }
std::vector<std::string> Model::bodies() const { return impl_->bodies; }
std::vector<std::pair<std::string, std::string>> Model::elements() const { return impl_->elements; }
std::vector<std::string> Model::columns() const { return impl_->columns; }
double Model::t_end() const { return impl_->t_end; }

const std::vector<double>& Results::series(const std::string& column) const {
  for (std::size_t k = 0; k < columns.size() && k < values.size(); ++k)
    if (columns[k] == column) return values[k];
  throw InputError("no result column '" + column + "'" + suggestion(column, columns) +
                   "; columns are t, <body>.x|y|theta|vx|vy|omega and <element>.<output> (Model::columns lists them)");
}

Results run(const Model& model, const RunSettings& settings, const std::atomic<bool>* stop) {
  const auto& m = Access::impl(model);
  RunOverrides overrides;
  // A name the table does not know goes to the loader as given, which refuses it as it refuses
  // --integrator's and the file's: one check, one message.
  std::vector<OptionSetting> unknown_integrator;
  if (settings.integrator) {
    overrides.integrator = integrator_from_name(*settings.integrator);
    if (!overrides.integrator)
      unknown_integrator.push_back({"simulation.integrator=" + json_string(*settings.integrator),
                                    "RunSettings.integrator = " + *settings.integrator});
  }
  overrides.t_end = settings.t_end;
  overrides.rtol = settings.rtol;
  overrides.atol = settings.atol;
  overrides.dt = settings.dt;
  overrides.output_interval = settings.output_interval;
  overrides.force_dt = settings.force_dt;
  // Through the loader, as the command line's options: checked and listed in the provenance alike.
  std::vector<OptionSetting> options = option_settings(overrides, OverrideSource::RunSettings);
  options.insert(options.begin(), unknown_integrator.begin(), unknown_integrator.end());
  const LoadedModel file = load_model_text(m.text, m.source, m.settings, options);
  const railcrash::Model& loaded = file.model;

  RunReport report = run_model(loaded, file.run_spec, "", stop, false, /*keep_in_memory=*/true, "csv", settings.timings);
  Results results;
  results.columns = std::move(report.columns);
  results.values = std::move(report.series);
  for (const EventRecord& e : report.outcome.events) results.events.push_back(Event{e.t, e.element, e.what, e.value});
  results.summary_json = std::move(report.summary_json);

  const RunOutcome& o = report.outcome;
  Summary& s = results.summary;
  s.ok = o.ok;
  s.message = o.message;
  s.integrator = report.integrator;
  s.t_reached = o.t_reached;
  s.steps = o.stats.steps;
  s.wall_seconds = o.stats.wall_seconds;
  s.energy_balance_error = EnergyBalance::between(o.initial_energy, o.final_energy).error();
  s.max_constraint_residual = o.max_constraint_residual;
  s.accuracy_warnings = accuracy_warnings(accuracy_facts(o, report.integrator, loaded.units));
  for (const railcrash::CarCrush& car : report.car_crush) s.cars.push_back(CarCrush{car.car, car.max_crush, car.t});
  const double g = standard_gravity(loaded);
  for (std::size_t i = 0; i < report.acceleration_peaks.size(); ++i) {
    const AccelerationPeaks& p = report.acceleration_peaks[i];
    s.peak_accelerations.push_back(PeakAcceleration{loaded.bodies()[i].name, p.magnitude, p.magnitude / g, p.t_magnitude});
  }
  s.has_responses = report.has_responses;
  s.r1 = report.responses.r1;
  s.r2 = report.responses.r2;
  s.r3 = report.responses.r3;
  return results;
}

// ---- ModelBuilder: writes a model file in YAML flow style ----

namespace {

/// A number YAML reads back exactly; non-finite values become words the loader rejects by key.
std::string yaml_number(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", value);
  return buffer;
}

std::string yaml_list(const std::vector<double>& values) {
  std::string out = "[";
  for (std::size_t k = 0; k < values.size(); ++k) out += (k ? ", " : "") + yaml_number(values[k]);
  return out + "]";
}

std::string yaml_point(const Point& p) {
  return "{body: " + json_string(p.body) + ", at: " + yaml_list({p.x, p.y}) + "}";
}

std::string yaml_parameter(const Parameter& value) {
  if (const auto* number = std::get_if<double>(&value)) return yaml_number(*number);
  if (const auto* flag = std::get_if<bool>(&value)) return *flag ? "true" : "false";
  if (const auto* list = std::get_if<std::vector<double>>(&value)) return yaml_list(*list);
  std::string out = "[";
  const auto& table = std::get<std::vector<std::vector<double>>>(value);
  for (std::size_t k = 0; k < table.size(); ++k) out += (k ? ", " : "") + yaml_list(table[k]);
  return out + "]";
}

}  // namespace

ModelBuilder::ModelBuilder(std::string name, std::string units) : name_(std::move(name)), units_(std::move(units)) {}

ModelBuilder& ModelBuilder::gravity(double x, double y) {
  gravity_ = std::array<double, 2>{x, y};
  return *this;
}

ModelBuilder& ModelBuilder::body(const BodySpec& b) {
  bodies_.push_back("{name: " + json_string(b.name) + ", mass: " + yaml_number(b.mass) + ", inertia: " + yaml_number(b.inertia) +
                    ", position: " + yaml_list({b.x, b.y}) + ", angle: " + yaml_number(b.angle) +
                    ", velocity: " + yaml_list({b.vx, b.vy}) + ", angular_velocity: " + yaml_number(b.angular_velocity) +
                    (b.car.empty() ? std::string() : ", car: " + json_string(b.car)) + "}");
  return *this;
}

ModelBuilder& ModelBuilder::element(const std::string& name, const std::string& type, const std::vector<Point>& points,
                                    const std::map<std::string, Parameter>& parameters) {
  std::string text = "{name: " + json_string(name) + ", type: " + json_string(type) + ", points: [";
  for (std::size_t k = 0; k < points.size(); ++k) text += (k ? ", " : "") + yaml_point(points[k]);
  text += "]";
  for (const auto& [key, value] : parameters) text += ", " + json_string(key) + ": " + yaml_parameter(value);
  elements_.push_back(text + "}");
  return *this;
}

ModelBuilder& ModelBuilder::force(const Point& at, double fx, double fy) {
  loads_.push_back("{type: force, body: " + json_string(at.body) + ", at: " + yaml_list({at.x, at.y}) +
                   ", value: " + yaml_list({fx, fy}) + "}");
  return *this;
}

ModelBuilder& ModelBuilder::force(const Point& at, const std::vector<std::array<double, 3>>& table) {
  std::string rows = "[";
  for (std::size_t k = 0; k < table.size(); ++k)
    rows += std::string(k ? ", " : "") + "[" + yaml_number(table[k][0]) + ", " + yaml_list({table[k][1], table[k][2]}) + "]";
  loads_.push_back("{type: force, body: " + json_string(at.body) + ", at: " + yaml_list({at.x, at.y}) + ", value: " + rows + "]}");
  return *this;
}

ModelBuilder& ModelBuilder::moment(const std::string& body, double value) {
  loads_.push_back("{type: moment, body: " + json_string(body) + ", value: " + yaml_number(value) + "}");
  return *this;
}

ModelBuilder& ModelBuilder::simulation(const RunSettings& settings) {
  simulation_ = settings;
  return *this;
}

std::string ModelBuilder::yaml() const {
  std::ostringstream y;
  y << "railcrash: 1\nname: " << json_string(name_) << "\nunits: " << json_string(units_) << "\n";
  if (gravity_) y << "gravity: " << yaml_list({(*gravity_)[0], (*gravity_)[1]}) << "\n";
  y << "bodies:\n";
  for (const std::string& b : bodies_) y << "  - " << b << "\n";
  if (!elements_.empty()) y << "elements:\n";
  for (const std::string& e : elements_) y << "  - " << e << "\n";
  if (!loads_.empty()) y << "loads:\n";
  for (const std::string& l : loads_) y << "  - " << l << "\n";
  const RunSettings& s = simulation_;
  y << "simulation:\n  t_end: " << yaml_number(s.t_end.value_or(1.0)) << "\n";
  if (s.integrator) y << "  integrator: " << json_string(*s.integrator) << "\n";
  if (s.rtol) y << "  rtol: " << yaml_number(*s.rtol) << "\n";
  if (s.atol) y << "  atol: " << yaml_number(*s.atol) << "\n";
  if (s.dt) y << "  dt: " << yaml_number(*s.dt) << "\n";
  if (s.output_interval) y << "  output_interval: " << yaml_number(*s.output_interval) << "\n";
  if (s.force_dt) y << "  force_dt: true\n";
  return y.str();
}

// No source name: the text is generated, so a line number would mean nothing to the user;
// the messages name the element, body or key instead.
Model ModelBuilder::build() const { return Model::from_yaml(yaml(), ""); }

}  // namespace railcrash::api
