// The crashworthiness criteria of a design collision scenario (the model file's `scenario:`
// section, written by `railcrash scenario`; scenario/en15227.hpp) and their evaluation after
// a run, for summary.json ("scenario") and the run report.
//
// The section names everything the criteria are measured on explicitly (it does not rely on
// body or element names):
//   scenario:
//     standard: EN 15227        number: 1        category: C-I
//     closing_speed: 393.7      # [length/time] what the scenario was built with
//     mean_deceleration: {limit: 1930.4, cfc: 60, source: "...", bodies: [s1_center_body, ...]}
//     survival_space: {limit: 1.97, source: "...", cars: [s1, t1], excluded: [wagon_buffers],
//                      gauges: [{name: s1, front: s1_bolster_body, rear: s1_rear_body}, ...]}
//     override: {limit: 3.94, source: "...", interface: anticlimber,
//                wheel_lift_limit: 0.83, wheel_lift_source: "...", wheels: [s1_front_truck_wheel_1, ...]}
// Limits are in the model's units ([length/time^2] for the deceleration, [length] otherwise);
// `source` says where each value comes from (the standard's clause, or "required input").
//
// Criteria (each with value, limit, margin = limit - value and pass = value <= limit):
//   mean deceleration  per body: its longitudinal velocity vx(t), low-pass filtered at the
//                      channel class `cfc` (results/cfc_filter.hpp), then the collision pulse
//                      of results/crash_pulse.hpp: |velocity change| / duration of the collision.
//   survival space     per car (`cars:`): the largest loss of the car's survival space over the
//                      run: the sum of its crush outputs (OutputRole::Crush) as
//                      car_elements_crush_at sums them (an element between two cars by half),
//                      each declared crush zone (`zones: [{element: E, stroke: S}]`) counting
//                      only its crush beyond its stroke S, and without the `excluded:` elements
//                      (the struck wagon's buffers or obstacle: not the train's). A lumped car's
//                      bodies are rigid, so its length shortens only in its crush elements: a car
//                      whose crush stays within its zones' strokes keeps its survival space
//                      (value 0, a pass); one whose zone bottoms out loses what it crushes beyond.
//                      A car with no crush element at all is "not measured" (a fail);
//   survival gauge     per gauge (`gauges:`, optional, beside): the largest shortening of the
//                      distance between the two bodies' centres of gravity, L(0) - L(t).
//   override           the interface anticlimber's vertical_offset: largest |v(t) - v(0)| (the
//                      vertical relative displacement of the faces), and its `override` output
//                      (the faces have slid past each other: fails whatever the limit); or,
//                      with `bodies: [A, B]` instead of `interface`, the largest change of
//                      y_B - y_A (scenario 2: the train's front end and the wagon); scenario 3
//                      has neither (and no override limit): only the wheel lift;
//                      wheel lift: the largest lift max(0, -penetration) of the listed wheel_rail
//                      elements (the leading bogies' wheels);
//                      wheel unloading (`rail_supports:`, slider_joints holding a bogie on the
//                      rail, for cars without wheel_rail elements): the largest unloading
//                      (Q0 - Q) / Q0 of the rail's normal reaction Q against its value Q0 at the
//                      start (the static wheel load); at 1 the rail would have to pull the bogie
//                      down, i.e. its wheels would lift: limit 1, a physical bound, not a value
//                      of the standard.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "railcrash/model/model_io.hpp"
#include "railcrash/results/results.hpp"
#include "railcrash/solver/integrator.hpp"

namespace YAML {
class Node;
}

namespace railcrash {

class Model;

struct ScenarioCriteria {
  std::string standard;           // e.g. "EN 15227"
  int number = 0;                 // scenario number
  std::string category;           // C-I .. C-IV
  double closing_speed = 0.0;     // [length/time]

  std::vector<std::string> passenger_bodies;
  double deceleration_limit = 0.0;  // [length/time^2]
  double cfc = 60.0;                // channel frequency class of the velocity filter
  std::string deceleration_source;

  struct Gauge {
    std::string name, front_body, rear_body;
  };
  std::vector<std::string> survival_cars;  // cars (bodies' car:) whose crush outputs are the survival-space loss
  std::vector<std::string> survival_excluded;  // crush elements that are not the train's (the struck body's)
  struct Zone {
    std::string element;
    double stroke = 0.0;  // [length] crush allowed before the survival space behind it is reached
  };
  std::vector<Zone> survival_zones;  // declared crush zones
  std::vector<Gauge> survival_gauges;
  double survival_limit = 0.0;  // [length] largest allowed shortening
  std::string survival_source;

  std::string interface_element;   // anticlimber, or "" when interface_bodies is used
  std::vector<std::string> interface_bodies;  // two bodies: vertical relative displacement of their c.g.s
  double override_limit = 0.0;     // [length] largest vertical relative displacement
  std::string override_source;
  std::vector<std::string> wheels; // wheel_rail elements of the leading bogies
  std::vector<std::string> rail_supports;  // slider_joints holding the leading bogies on the rail
  double wheel_lift_limit = 0.0;   // [length]
  std::string wheel_lift_source;

  /// Scenarios 1 and 2 have an interface whose vertical relative displacement is the override
  /// criterion; scenario 3 (an obstacle) has none.
  bool has_interface() const { return !interface_element.empty() || !interface_bodies.empty(); }
};

/// Reads and checks a `scenario:` section against the model's bodies and elements, its lengths,
/// speeds and decelerations times `length_scale` (the file's units to the model's). `fail`
/// throws an InputError naming the file and line of the node (model_io's reader). Registered
/// with model_io as its ScenarioSectionReader.
std::shared_ptr<const ScenarioCriteria> read_scenario_section(const YAML::Node& section, const Model& model, double length_scale,
                                                              const SectionFail& fail);

/// One criterion's outcome.
struct CriterionResult {
  std::string criterion;  // "mean_deceleration", "survival_space", "override", "wheel_lift"
  std::string subject;    // body, gauge, interface element or wheel
  double value = 0.0;
  double limit = 0.0;
  bool pass = false;
  std::string note;       // e.g. "collision not complete at the end of the run"
  double margin() const { return limit - value; }
};

// ---- the criteria on histories (times increasing, one value per time) ----

/// Mean deceleration [length/time^2] of a body over its collision, from vx(t) filtered at `cfc`
/// (unfiltered when the samples are too few or too coarse for the filter); `complete` tells
/// whether the velocity change ended before the record.
double filtered_mean_deceleration(const std::vector<double>& times, const std::vector<double>& vx, double cfc, bool* complete);
/// Largest shortening L(0) - L(t) [length] (0 if the length never falls below L(0)).
double largest_shortening(const std::vector<double>& lengths);
/// Largest |v(t) - v(0)|.
double largest_change(const std::vector<double>& values);
/// Largest lift max(0, -penetration) of a wheel [length].
double largest_lift(const std::vector<double>& penetration);
/// The static load Q0 of a rail reaction history: its first non-zero value (explicit Euler's
/// penalty joints report no reaction in the first sample); 0 if there is none.
double static_load(const std::vector<double>& reaction);
/// Largest unloading (Q0 - Q) / Q0 of a rail reaction Q against its static load Q0 (either
/// sign); infinity when Q0 is 0 (no static load to compare with).
double largest_unloading(const std::vector<double>& reaction);
/// The same with Q0 given (the static wheel load [force]): the lowest Q / Q0 from the first
/// non-zero sample on (an explicit run's penalty joints carry nothing at t = 0).
double largest_unloading(const std::vector<double>& reaction, double static_load);

/// Collects the histories during a run and evaluates the criteria at the end.
class ScenarioTracker : public RunObserver {
 public:
  ScenarioTracker(const DaeSystem& system, const ScenarioCriteria& criteria);
  void sample(double t, const double* y, const double* lambda, const double* quadratures, const double* outputs) override;
  /// The extrema of the crush, gauge, interface and wheel criteria also from every accepted
  /// step and both sides of every event (the mean deceleration stays on the output rows: it
  /// filters a uniform record).
  void step(double t, const double* y, const double* lambda, const double* outputs, const FreshOutputs& fresh) override;
  bool observes_steps() const override { return true; }
  /// The survival cars' crush columns, the interface's offset and override, the wheels' and supports'.
  void mark_step_columns(std::vector<char>& columns) const override;
  std::vector<CriterionResult> results() const;
  /// The scenario and its criteria as a JSON object (summary.json's "scenario").
  std::string json() const;

 private:
  const DaeSystem& system_;
  const ScenarioCriteria& criteria_;
  CriterionResult interface_result() const;
  /// The rail supports' reactions [force] at the state (t, y) with consistent multipliers.
  std::vector<double> static_loads(double t, const double* y) const;
  /// Q0 of rail support k [force]: static_load_, or, when it could not be computed, the first
  /// non-zero sample.
  double wheel_static_load(std::size_t k) const;
  /// Crush of survival car k [length] from the element outputs.
  double car_crush_now(std::size_t k, const double* outputs) const;

  std::vector<int> passenger_index_, front_index_, rear_index_;
  std::vector<CarCrush> crush_of_cars_;                 // of survival_cars, in their order
  std::vector<double> crush_scratch_;                   // their elements' outputs evaluated at an event (car_crush_at)
  int vertical_offset_column_ = -1, override_column_ = -1;
  int interface_lower_ = -1, interface_upper_ = -1;  // bodies of interface_bodies
  std::vector<int> wheel_columns_, support_columns_;
  std::vector<std::vector<double>> allowed_;  // per survival car: each column's allowed stroke (shared_crush)
  std::vector<double> times_;
  std::vector<std::vector<double>> vx_, lengths_, penetration_, car_crush_, reaction_;
  /// Q0 per rail support [force] (empty when no consistent multipliers exist): its reaction at t = 0 with the multipliers consistent with the
  /// start (the static load), whatever the integrator. Euler's penalty joints carry nothing at
  /// t = 0 and overshoot on their first step (231 kN against the static 200 kN on
  /// models/scenarios/scenario2_emu3.yaml), so Q0 from its samples measured unloading from
  /// too high a load.
  std::vector<double> static_load_;
  std::vector<double> vertical_offset_;
  bool overridden_ = false;
  struct StepExtremes {                  // from step(), beside the rows' histories
    std::vector<double> shortening;      // [length] per survival gauge
    std::vector<double> car_crush;       // [length] per survival car
    std::vector<double> lift;            // [length] per wheel
    std::vector<double> lowest_load;     // [-] per rail support: smallest Q / Q0
    double offset_change = 0.0;          // [length] interface
  } step_extremes_;
};

}  // namespace railcrash
