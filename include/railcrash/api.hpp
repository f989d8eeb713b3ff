// railcrash's public C++ interface: the one header (with error.hpp) that `cmake --install`
// installs and `find_package(railcrash)` gives you. Everything else under include/railcrash is
// internal and may change without notice; this header changes only with the version number.
//
//   #include <railcrash/api.hpp>
//   namespace rc = railcrash::api;
//   rc::Model model = rc::Model::load("models/report/final_two_car.yaml",
//                                     {"elements.anticlimber.horizontal_yield_deflection*=1.2"});
//   rc::RunSettings settings;
//   settings.integrator = "ida";
//   settings.rtol = 1e-4;
//   rc::Results results = rc::run(model, settings);       // nothing is written to disk
//   const std::vector<double>& x = results.series("car1_center_body.x");
//
// Models are the YAML model files of the command line (README "Model file"); a ModelBuilder
// writes one in code. Settings are the command line's --set: KEY=VALUE (a YAML value) or
// KEY*=FACTOR, with KEY one of section.key, bodies.<name>.<key>, elements.<name>.<key> or a
// top-level key. Results are those of `railcrash run` (timeseries.csv, events.csv,
// summary.json), in memory.
//
// Errors: a model or setting the user must change throws railcrash::InputError, whose message
// names the file, line, element or key and what to change; a run the solver cannot finish does
// not throw but returns with ok = false and the reason (as the command line does).
//
// Threads: a Model is immutable and may be shared; run() may be called from several threads
// at once, on the same model or on different ones (each run reads its own copy).
#pragma once

#include <array>
#include <atomic>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "railcrash/core/error.hpp"

namespace railcrash::api {

/// Version of the library, "MAJOR.MINOR.PATCH".
const char* version();

/// A checked model, ready to run. Immutable and cheap to copy.
class Model {
 public:
  /// Reads and checks a model file, then applies the settings in order.
  static Model load(const std::string& path, const std::vector<std::string>& settings = {});
  /// Same, from YAML text; `source` names it in error messages (empty: no file prefix).
  static Model from_yaml(const std::string& text, const std::string& source = "<string>",
                         const std::vector<std::string>& settings = {});

  /// A copy with more settings applied after the ones so far (checked now).
  Model with(const std::vector<std::string>& settings) const;

  const std::string& name() const;
  /// The model file ("" for a model from text).
  const std::string& path() const;
  /// The model's YAML text as read, before the settings.
  const std::string& yaml() const;
  /// Every setting applied, in order.
  const std::vector<std::string>& settings() const;
  /// "SI" or "in-lbf-s": the units of every number in and out.
  const std::string& units() const;
  std::vector<std::string> bodies() const;
  /// (name, type) of every element, in file order.
  std::vector<std::pair<std::string, std::string>> elements() const;
  /// Names of the results' columns (t, then <body>.x|y|theta|vx|vy|omega, then <element>.<output>).
  std::vector<std::string> columns() const;
  /// The model's own end time [s].
  double t_end() const;

 private:
  struct Impl;
  explicit Model(std::shared_ptr<const Impl> impl);
  std::shared_ptr<const Impl> impl_;
  friend struct Access;
};

/// Integrator settings for one run; unset fields keep the model's simulation section. Each set
/// field is applied as the command line's option is (simulation.KEY=VALUE through the loader:
/// the same checks and messages, which name it "RunSettings.KEY = VALUE") and is listed in the
/// run's provenance (summary_json's "settings").
struct RunSettings {
  std::optional<std::string> integrator;      // "auto", "ida" or "euler"
  std::optional<double> t_end;                // [s]
  std::optional<double> rtol;                 // ida: relative tolerance
  std::optional<double> atol;                 // ida: absolute tolerance on lengths [the model file's length
                                              // unit: mm for an mm-t-s-N model, as its simulation.atol and --atol]
  std::optional<double> dt;                   // euler: step [s]
  std::optional<double> output_interval;      // [s] time between samples
  bool force_dt = false;                      // euler: accept a step above the stability limit
  bool timings = false;                       // the wall time split by phase: summary_json's stats.seconds
};

/// A committed mode change: contact, yield, unloading, rupture, override, ...
struct Event {
  double t = 0.0;         // [s]
  std::string element;
  std::string event;
  double value = 0.0;     // the quantity that crossed its threshold, in model units
};

/// One car's largest crush (cars are declared by the bodies' `car:` key; README).
struct CarCrush {
  std::string car;
  double max_crush = 0.0;  // [length]
  double t = 0.0;          // [s]
};

/// One body's largest acceleration magnitude over the samples.
struct PeakAcceleration {
  std::string body;
  double magnitude = 0.0;  // [length/s^2]
  double g = 0.0;          // in standard gravities
  double t = 0.0;          // [s]
};

/// The main figures of summary.json; `Results::summary_json` has all of it.
struct Summary {
  bool ok = false;
  std::string message;             // why the run stopped early ("" when ok)
  std::string integrator;          // "auto", "ida" or "euler" (summary_json's integrator_used: which ran)
  double t_reached = 0.0;          // [s]
  long steps = 0;
  double wall_seconds = 0.0;       // [s] integration only
  double energy_balance_error = 0.0;       // [energy] kinetic + elastic + gravity + dissipated - initial - external work
  double max_constraint_residual = 0.0;    // [length] largest |Phi| over the samples
  std::vector<std::string> accuracy_warnings;  // summary.json's: energy drift or joint opening past the limits
                                               // of results/accuracy_check.hpp, each with what to change
  std::vector<CarCrush> cars;
  std::vector<PeakAcceleration> peak_accelerations;  // every body, in model order
  bool has_responses = false;      // the model has a responses section: R1-R3 below
  double r1 = 0.0, r2 = 0.0, r3 = 0.0;
};

/// What a run gives, in memory: the columns of timeseries.csv, events.csv and summary.json.
struct Results {
  std::vector<std::string> columns;         // "t", "<body>.x", ..., "<element>.<output>"
  std::vector<std::vector<double>> values;  // values[k]: column k at every sample
  std::vector<Event> events;
  Summary summary;
  std::string summary_json;                 // the text railcrash run writes to summary.json

  bool ok() const { return summary.ok; }
  /// Sample times [s].
  const std::vector<double>& t() const { return series("t"); }
  /// One column over the samples; InputError naming the nearest column if there is none.
  const std::vector<double>& series(const std::string& column) const;
};

/// Runs the model with the settings; *stop set to true from another thread ends the run early
/// (ok = false). Throws InputError for bad settings, before anything runs.
Results run(const Model& model, const RunSettings& settings = {}, const std::atomic<bool>* stop = nullptr);

/// An element parameter: a number, a flag, a list of numbers or a table of rows.
using Parameter = std::variant<double, bool, std::vector<double>, std::vector<std::vector<double>>>;

/// A body of a model built in code (fields as in the model file's bodies).
struct BodySpec {
  std::string name;
  double mass = 0.0;               // [mass]
  double inertia = 0.0;            // [mass*length^2] centroidal; 0 = point mass
  double x = 0.0, y = 0.0;         // [length] centre of mass
  double angle = 0.0;              // [rad]
  double vx = 0.0, vy = 0.0;       // [length/s]
  double angular_velocity = 0.0;   // [rad/s]
  std::string car{};               // the car the body belongs to; "" = none (track, barrier, ...)
};

/// A connection point: a body ("ground" for the fixed one) and an offset from its centre of
/// mass in the body's frame [length].
struct Point {
  std::string body;
  double x = 0.0, y = 0.0;
};

/// Builds a model in code. It writes the same YAML as a model file, so build() checks it with
/// the same rules and messages (which name the element or body; there is no line to name).
class ModelBuilder {
 public:
  /// units: "SI" or "in-lbf-s". Gravity defaults to standard gravity in -y.
  explicit ModelBuilder(std::string name, std::string units = "SI");

  ModelBuilder& gravity(double x, double y);  // [length/s^2]
  ModelBuilder& body(const BodySpec& body);
  /// An element by type name (README "Element reference") with its parameters.
  ModelBuilder& element(const std::string& name, const std::string& type, const std::vector<Point>& points,
                        const std::map<std::string, Parameter>& parameters = {});
  /// A constant force (Fx, Fy) [force] at a body point.
  ModelBuilder& force(const Point& at, double fx, double fy);
  /// A force interpolated linearly in time: rows (t, Fx, Fy).
  ModelBuilder& force(const Point& at, const std::vector<std::array<double, 3>>& table);
  /// A constant moment [force*length] on a body.
  ModelBuilder& moment(const std::string& body, double value);
  /// The simulation section (t_end defaults to 1 s).
  ModelBuilder& simulation(const RunSettings& settings);

  /// The model file this builder describes.
  std::string yaml() const;
  /// Checks and returns the model; InputError names what to change.
  Model build() const;

 private:
  std::string name_, units_;
  std::optional<std::array<double, 2>> gravity_;
  std::vector<std::string> bodies_, elements_, loads_;  // YAML flow maps, one per entry
  RunSettings simulation_;
};

}  // namespace railcrash::api
