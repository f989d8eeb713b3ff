// The report's response parameters (Section 4.1; see models/report/TRANSCRIPTION.md §10):
//   R1 = axial crush / reference deformation
//        axial crush: the largest shortening of the model's crush gauges (point pairs along
//        each car), summed over the cars ("the total crush of the cars", Section 5) or, with
//        `crush: largest`, the largest single car's; with `crush: anticlimber`, the
//        anticlimber's largest horizontal deformation (the crush of both car ends when the
//        element carries the two ends in series, as the report's two-car model does)
//   R2 = largest vertical anticlimber force / vertical yield force        (no override)
//      = 1 + relative horizontal velocity / reference velocity             (override)
//        the yield force is the typical anticlimber's (elastic slope x yield deflection, or
//        `vertical_yield_force`), fixed for every run of a study (report Section 5); the
//        relative velocity is that of the two anticlimber bodies along x at the override
//        event (the report takes it when the overriding end sill reaches the collision post,
//        which the planar model has no mass for: an approximation, stated in summary.json)
//   R3 = max(R1, R2) when both are below 1, else R1 + R2 (reading R-1)
// The largest force and crush are taken over the output samples, the ends of all accepted
// steps and both sides of every mode change (RunObserver::step): the output interval does not
// change them.
// R2's largest vertical force is taken over the whole run or, as `vertical_force_window`
// says, only until the anticlimber first unloads horizontally (largest crush) or first
// separates (a reading: models/report/README.md).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "railcrash/integrator.hpp"

namespace railcrash {

struct Responses {
  double r1 = 0.0, r2 = 0.0, r3 = 0.0;
  std::vector<double> max_crush;        // [length] per gauge
  double max_vertical_force = 0.0;      // [force] anticlimber, |vertical force|
  double max_anticlimber_crush = 0.0;   // [length] anticlimber, largest horizontal deformation
  double vertical_yield_force = 0.0;    // [force]
  bool overridden = false;
  double override_time = -1.0;          // [time]
  double override_relative_velocity = 0.0;  // [length/time]
};

/// Follows a run and computes the responses; add it as an observer.
class ResponseTracker : public RunObserver {
 public:
  ResponseTracker(const DaeSystem& system, const ResponseSettings& settings);
  void sample(double t, const double* y, const double* lambda, const double* quadratures, const double* outputs) override;
  void event(const EventRecord& record, const double* y) override;
  /// The largest crush and forces from every accepted step and both sides of every event.
  void step(double t, const double* y, const double* lambda, const double* outputs, const FreshOutputs& fresh) override;
  bool observes_steps() const override { return true; }
  Responses result() const;
  /// The responses as a JSON object (for summary.json).
  std::string json() const;

 private:
  double gauge_length(const CrushGauge& gauge, const double* y) const;
  /// Updates the largest crush and forces with the state y and its element outputs (those
  /// `fresh` has).
  void track_extrema(const double* y, const double* outputs, const FreshOutputs& fresh);

  const DaeSystem& system_;
  ResponseSettings settings_;
  int anticlimber_element_ = -1;   // element index
  int vertical_force_column_ = -1; // index into DaeSystem::outputs
  int horizontal_deformation_column_ = -1;
  std::vector<double> initial_length_;
  Responses responses_;
  bool started_ = false;
  bool vertical_window_closed_ = false;  // R2's window (ResponseSettings::vertical_force_window) has ended
};

}  // namespace railcrash
