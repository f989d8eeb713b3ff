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
//        relative velocity is that of the two anticlimber bodies along x "at the time the
//        end sill of the overriding car hits the collision post of the other car" (report
//        Section 4.1; issue 40): the first time after the override that the anticlimber's
//        horizontal deformation d_h (the faces' approach since they first touched; it goes on
//        growing as the overriding end slides over the other) reaches
//        `collision_post_distance` (default `reference_crush`, which the report defines by the
//        same distance, "the distance from the anticlimber to the collision post"), linearly
//        interpolated between the two tracked states (accepted steps, samples, both sides of
//        events) around it. If d_h is already past it at the override, the post is reached at
//        once (the velocity at the override); if it never gets there (the cars part first),
//        the end sill never hits the post and the relative velocity is 0 (R2 = 1).
//        `override_velocity_at: override` is the labelled variant from before issue 40: the
//        velocity at the override event.
//   R3 = max(R1, R2) when both are below 1, else R1 + R2 (reading R-1)
// The largest force and crush are taken over the output samples, the ends of all accepted
// steps and both sides of every mode change (RunObserver::step): the output interval does not
// change them.
// R2's largest vertical force is taken over the whole run or, as `vertical_force_window`
// says, only until the anticlimber first unloads horizontally (largest crush) or first
// separates (a reading: models/report/README.md).
#pragma once

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "railcrash/model/run_spec.hpp"
#include "railcrash/solver/integrator.hpp"

namespace railcrash {

struct Responses {
  double r1 = 0.0, r2 = 0.0, r3 = 0.0;
  std::vector<double> max_crush;        // [length] per gauge
  double max_vertical_force = 0.0;      // [force] anticlimber, |vertical force|
  double max_anticlimber_crush = 0.0;   // [length] anticlimber, largest horizontal deformation
  double vertical_yield_force = 0.0;    // [force]
  bool overridden = false;
  double override_time = -1.0;          // [time]
  double override_relative_velocity = 0.0;  // [length/time] the one R2 uses (see above)
  double relative_velocity_at_override = 0.0;   // [length/time] at the override event
  bool collision_post_reached = false;          // the end sill reached the collision post after the override
  double collision_post_time = -1.0;            // [time] when it did
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
  /// The anticlimber's vertical force and horizontal deformation (the gauges read y alone).
  void mark_step_columns(std::vector<char>& columns) const override;
  Responses result() const;
  /// The responses as a JSON object (for summary.json).
  std::string json() const;

 private:
  double gauge_length(const CrushGauge& gauge, const double* y) const;
  /// Updates the largest crush and forces with the state y and its element outputs (those
  /// `fresh` has).
  void track_extrema(const double* y, const double* outputs, const FreshOutputs& fresh);
  /// Relative velocity of the anticlimber's two bodies along x in state y.
  double relative_velocity(const double* y) const;
  /// After an override: finds when the faces' approach reaches the collision post.
  void track_collision_post(double t, const double* y, const double* outputs, const FreshOutputs& fresh);

  const DaeSystem& system_;
  ResponseSettings settings_;
  int anticlimber_element_ = -1;   // element index
  int vertical_force_column_ = -1; // index into DaeSystem::outputs
  int horizontal_deformation_column_ = -1;
  std::vector<double> initial_length_;
  Responses responses_;
  bool started_ = false;
  bool vertical_window_closed_ = false;  // R2's window (ResponseSettings::vertical_force_window) has ended
  // For the collision post: the latest tracked state (with a fresh horizontal deformation)
  // before the override, and every one from the override on.
  struct TrackedState {
    double t, crush, velocity;  // [time], d_h [length], relative velocity along x [length/time]
  };
  bool have_last_ = false;
  TrackedState last_{0.0, 0.0, 0.0};
  std::vector<TrackedState> after_override_;
  double at_post_by_ = std::numeric_limits<double>::infinity();  // [time] a state at or past the post
  /// Sets R2's relative velocity and the collision post's time from after_override_.
  void find_collision_post(Responses& r) const;
};

}  // namespace railcrash
