// The run loop's guard against an element chattering on a mode boundary: a mode change that
// repeats at one instant, again and again (a law whose two modes each send it back to the
// other there). Each such change is a located event and a restart, so the run crawls at steps
// of 1e-11 s and would not end within hours: emu3_unit_collision at --rtol 1e-3 logged 1,153,628
// events in 30 s before the hysteresis laws' exits took the rate into account
// (bench/HISTORY.md, "Event storms"). The guard stops such a run with a message that names the
// element; what was computed up to there is kept.
#pragma once

#include <string>
#include <unordered_map>

#include "railcrash/solver/dae_system.hpp"

namespace railcrash {

class ChatterGuard {
 public:
  /// Changes of one element in a row, each at one instant with the one before, that stop a run.
  static constexpr long kLimit = 10000;
  /// What counts as one instant: two changes at most this fraction of the run's end time apart.
  static constexpr double kInstant = 1e-9;

  explicit ChatterGuard(double t_end, long limit = kLimit) : instant_(kInstant * t_end), limit_(limit) {}

  /// Takes the next event of the run; true when its element has now changed mode `limit` times
  /// in a row, each at one instant with its own change before (other elements' events in
  /// between do not count: two gears may chatter at once). Then first_time() and count() say
  /// since when and how often.
  bool record(const EventRecord& event);
  long count() const { return tripped_.count; }
  double first_time() const { return tripped_.first_time; }  // [time]

 private:
  struct Changes {  // an element's current run of changes at one instant
    double first_time = 0.0, last_time = 0.0;  // [time]
    long count = 0;
  };
  double instant_;  // [time]
  long limit_;
  std::unordered_map<std::string, Changes> changes_;  // by element name
  Changes tripped_;
};

}  // namespace railcrash
