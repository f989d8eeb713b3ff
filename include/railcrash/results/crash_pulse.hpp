// The crash pulse of one body: its collision interval and mean deceleration, the quantity
// crashworthiness standards limit for the occupied car bodies.
//
// From the body's longitudinal velocity samples vx(t) (its velocity change dv(t) = vx(t) - vx(t0)):
//   - first contact: the last sample before |dv| first exceeds 0.01 % of its largest value
//     (above the integrator's noise; a half-sine pulse's start is found 0.6 % of its duration late);
//   - end of the velocity change: the first sample, after |dv| has reached 90 % of its largest
//     value, at which |dv| stops growing (a local maximum; the car has reached the common speed or
//     separated). If |dv| grows to the end of the record, the end is the last sample and
//     `complete` is false (the run stopped during the collision);
//   - mean deceleration = |dv(end) - dv(start)| / (end - start), the velocity change over the
//     collision's duration (equal to the mean of the acceleration over that interval).
// A body whose velocity does not change (largest |dv| zero) has no collision (found = false).
#pragma once

#include <vector>

namespace railcrash {

struct CollisionPulse {
  bool found = false;              // the velocity changed at all
  bool complete = false;           // the velocity change ended before the record did
  double t_start = 0.0;            // [time] first contact
  double t_end = 0.0;              // [time] end of the velocity change
  double velocity_change = 0.0;    // [length/time] vx(t_end) - vx(t_start)
  double mean_deceleration = 0.0;  // [length/time^2] |velocity_change| / (t_end - t_start)
};

/// The collision pulse of one body from its velocity samples (times increasing).
CollisionPulse collision_pulse(const std::vector<double>& times, const std::vector<double>& velocity);

}  // namespace railcrash
