// A run's settings, apart from the physical model (model.hpp): how long and with which
// integrator (simulation), what the responses R1-R3 are measured on, which body points are
// written, and the scenario's criteria. The model file's `simulation:`, `responses:`,
// `outputs:` and `scenario:` sections; the loader returns one beside the Model (model_io.hpp:
// LoadedModel), and the run-level functions take the two side by side.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "railcrash/model/element.hpp"

namespace railcrash {

/// What the report's response parameters R1-R3 are measured on (responses.hpp).
struct CrushGauge {
  std::string name;
  PointRef front, rear;  // two points along one car
};

struct ResponseSettings {
  std::vector<CrushGauge> crush_gauges;
  bool total_crush = true;                    // R1 uses the sum over gauges (else the largest)
  bool crush_from_anticlimber = false;        // R1 uses the anticlimber's largest horizontal deformation
  double reference_crush = 0.0;               // [length] maximum "safe" crush
  std::string anticlimber;                    // element whose vertical force and override make R2
  std::optional<double> vertical_yield_force; // [force] default: the anticlimber's own
  double reference_velocity = 0.0;            // [length/time] velocity that fails the collision post
  /// When R2's relative horizontal velocity is taken after an override. The report (Section
  /// 4.1): "at the time the end sill of the overriding car hits the collision post of the
  /// other car".
  ///   CollisionPost  the first time after the override that the anticlimber's horizontal
  ///                  deformation (the faces' approach since they first touched, which goes on
  ///                  after the faces have passed each other) reaches collision_post_distance;
  ///   Override       at the override event itself (before issue 40; a labelled variant).
  enum class OverrideVelocityAt { CollisionPost, Override };
  OverrideVelocityAt override_velocity_at = OverrideVelocityAt::CollisionPost;
  double collision_post_distance = 0.0;       // [length] default: reference_crush (the report's
                                              // "distance from the anticlimber to the collision post")
  /// Over which part of the run R2's largest vertical force is taken (a reading; the report
  /// says only "maximum vertical force at anticlimbers"):
  ///   WholeRun          every output sample of the run;
  ///   UntilLargestCrush until the anticlimber's horizontal law first unloads (the cars have
  ///                     reached their common speed and begin to move apart);
  ///   UntilSeparation   until the anticlimber faces first separate.
  enum class VerticalForceWindow { WholeRun, UntilLargestCrush, UntilSeparation };
  VerticalForceWindow vertical_force_window = VerticalForceWindow::WholeRun;
  bool defined() const { return !crush_gauges.empty() || !anticlimber.empty(); }
};

/// An output request (the model file's `outputs:`): the motion of a point on a body, written
/// to timeseries.csv as <name>.x,<name>.y (position), <name>.vx,<name>.vy (velocity),
/// <name>.ax,<name>.ay (acceleration) after the element columns (results/output_points.hpp).
struct OutputPoint {
  std::string name;          // column prefix; default <body>_point<k>
  PointRef point;            // a body (not ground) and the offset from its centre of mass [length]
  bool position = true, velocity = true, acceleration = true;
  SourceLocation where;
};

/// ida: IDA + KLU on the DAE; euler: the report's explicit Euler with penalty joints; auto:
/// IDA, handing the run to Euler where Euler is the cheaper (auto_integrator.hpp).
enum class IntegratorKind { Ida, Euler, Auto };

/// The one table of the integrators' names in model files, options, messages and outputs, in
/// the order messages list them ("auto, ida or euler").
struct IntegratorName {
  IntegratorKind kind;
  const char* name;
};
inline constexpr IntegratorName kIntegratorNames[] = {
    {IntegratorKind::Auto, "auto"}, {IntegratorKind::Ida, "ida"}, {IntegratorKind::Euler, "euler"}};
/// The method a run of integrator auto reports when it handed the run from IDA to Euler
/// (summary.json's integrator_used, the studies' tables).
inline constexpr const char* kIdaThenEulerMethod = "ida+euler";
/// ... when IDA then took the run back from Euler and finished it (Euler's trial failed).
inline constexpr const char* kIdaEulerIdaMethod = "ida+euler+ida";

/// The integrator's name ("ida", "euler", "auto").
constexpr const char* integrator_name(IntegratorKind kind) {
  for (const IntegratorName& entry : kIntegratorNames)
    if (entry.kind == kind) return entry.name;
  return "?";
}
/// The integrator of a name, or nullopt for a name that is none of them.
std::optional<IntegratorKind> integrator_from_name(const std::string& name);
/// Every integrator's name, in the table's order.
std::vector<std::string> integrator_names();
/// The names for a message: "auto, ida or euler" (`quote`: each in it, e.g. "\"").
std::string integrator_names_text(const std::string& quote = "");

/// How IDA's error test weighs positions (simulation: position_tolerance; README "Position
/// tolerances"). Relative: SUNDIALS' form, rtol |q| + atol (atol default 0.1 rtol L).
/// Absolute: atol alone, with no part that grows with the distance from the model's origin
/// (atol default rtol V / omega: the speed scale over the model's highest frequency).
enum class PositionTolerance { Relative, Absolute };

/// The fill-reducing ordering of IDA's sparse LU factorization (KLU) (simulation:
/// linear_ordering). FewestEntries: AMD and COLAMD both factor the first Newton matrix and the
/// one whose factors hold fewer entries is kept (a tie keeps AMD). Amd, Colamd: that one alone.
/// The ordering changes only round-off, but round-off is what decides a chaotic quantity's last
/// digits (the report's R2: bench/HISTORY.md, "KLU's ordering chosen by fill").
enum class LinearOrdering { FewestEntries, Amd, Colamd };

/// IDA: the steps a Jacobian serves later setups by default (simulation: jacobian_kept_steps;
/// IdaSettings::jacobian_kept_steps; README "Jacobians kept").
inline constexpr long kDefaultJacobianKeptSteps = 20;  // [steps]

struct SimulationSettings {
  double t_end = 1.0;               // [time]
  IntegratorKind integrator = IntegratorKind::Auto;
  double rtol = 1e-6;               // ida: relative tolerance
  std::optional<double> atol;       // ida: absolute tolerance on lengths [length]; default derived from the model
  PositionTolerance position_tolerance = PositionTolerance::Relative;  // ida: how positions are weighed
  LinearOrdering linear_ordering = LinearOrdering::FewestEntries;    // ida: KLU's fill-reducing ordering
  long jacobian_kept_steps = kDefaultJacobianKeptSteps;  // [steps] ida: how long a Jacobian serves later setups (IdaSettings::jacobian_kept_steps; 0: every setup evaluates)
  double dt = 0.0;                  // euler: step [time]; 0 = 0.5 x stability limit
  double output_interval = 0.0;     // [time]; 0 = t_end / 500
  bool force_dt = false;            // euler: accept a step above the stability limit
  bool static_equilibrium = false;  // settle the bodies under gravity and loads at t = 0 first
  Element::PenaltyOverrides penalty;  // euler: model-wide penalty settings
  long max_steps = 10000000;        // [steps] either integrator may take; the run fails beyond (run --max-steps)
};

/// "" when `rtol` is a relative tolerance IDA can use (positive and finite), else the one
/// message about it: "WHAT must be a positive number (the relative tolerance; typical: 1e-6),
/// not VALUE". Every check of an rtol asks it: the model file's simulation: rtol, --rtol, the
/// API's run settings, a convergence study's tolerances and IDA's own. `typical`: the value the
/// message offers (a convergence study's reference wants a tight one: "1e-9").
std::string rtol_problem(double rtol, const std::string& what, const char* typical = "1e-6");

/// The most output rows a run may write: t_end / output_interval above it is refused.
constexpr double kMaxOutputRows = 1e6;  // [rows]

/// Why the settings' output rows exceed kMaxOutputRows ("" when they do not), with the figure
/// and the smallest output_interval that fits.
std::string output_rows_problem(const SimulationSettings& settings);

struct ScenarioCriteria;  // results/scenario_criteria.hpp (the results layer reads the `scenario:` section)

/// Everything a model file says about its run rather than its bodies, elements and loads.
struct RunSpec {
  SimulationSettings simulation;
  ResponseSettings responses;
  std::vector<OutputPoint> output_points;
  std::shared_ptr<const ScenarioCriteria> scenario;  // the `scenario:` section, if any
};

}  // namespace railcrash
