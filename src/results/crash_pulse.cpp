// Collision interval and mean deceleration of a body (definitions in the header).
#include "railcrash/results/crash_pulse.hpp"

#include <algorithm>
#include <cmath>

namespace railcrash {

CollisionPulse collision_pulse(const std::vector<double>& times, const std::vector<double>& velocity) {
  constexpr double kContactFraction = 1e-4;  // of the largest |dv|: first contact
  constexpr double kReachedFraction = 0.9;   // of the largest |dv|: the end may come from here on
  CollisionPulse pulse;
  const std::size_t n = std::min(times.size(), velocity.size());
  if (n < 2) return pulse;
  double largest = 0.0;
  for (std::size_t k = 0; k < n; ++k) largest = std::max(largest, std::abs(velocity[k] - velocity[0]));
  if (!(largest > 0.0)) return pulse;
  pulse.found = true;
  const auto change = [&](std::size_t k) { return std::abs(velocity[k] - velocity[0]); };
  std::size_t start = 0;
  while (start + 1 < n && change(start + 1) <= kContactFraction * largest) ++start;
  std::size_t end = start + 1;
  while (end < n && change(end) < kReachedFraction * largest) ++end;
  while (end + 1 < n && change(end + 1) > change(end)) ++end;
  pulse.complete = end + 1 < n;
  end = std::min(end, n - 1);
  pulse.t_start = times[start];
  pulse.t_end = times[end];
  pulse.velocity_change = velocity[end] - velocity[start];
  const double duration = pulse.t_end - pulse.t_start;
  pulse.mean_deceleration = duration > 0.0 ? std::abs(pulse.velocity_change) / duration : 0.0;
  return pulse;
}

}  // namespace railcrash
