// A run's discrete outcome (issue 40): which elements fractured, sheared, overrode or bottomed
// out, in which order and when, read from the run's events (events.csv, RunOutcome::events).
//
// A crash response jumps where the sequence of failures changes: a finite difference across
// such a jump is not a sensitivity. The signature names the sequence so that a study can say
// which runs are on the same branch as its base run (run 0), and which cross a change.
//
// Outcome events are the jumps of the element library, by the names the elements log
// (src/elements/*.cpp): "fracture" (draft gear, beam, nonlinear spring), "pin shear" (draft
// gear), "face shear failure" and "vertical overlap lost" (coupler end: the faces shear, or
// the couplers override), "crushing failure", "shear failure", "bending failure" and "override"
// (anticlimber), and bottoming ("bottomed ..." of a draft gear, "solid" after its pin sheared).
// Kinks (contact, unloading, reloading, yield, curve segments, slack taken up, separation of a
// crush front) are not outcomes: the force stays continuous across them. An event whose text
// joins several changes ("unloading, interlock released") is split at ", ".
//
// Only the first occurrence of each (element, outcome) counts: a gear that bottoms, comes off
// and bottoms again has bottomed once for the branch.
//
// Near-simultaneous outcomes. Outcomes closer in time than a window (kBranchWindow, 0.1 ms by
// default; times are in seconds in both unit systems) form one group, and a group is compared
// as a set: two draft gears that both fracture 41 us apart under the same train force are a
// tie, and which of the two goes first is not a different failure sequence. The window only
// joins outcomes into groups when each is within the window of the previous one.
//
// Two runs are on the same branch when their order-only forms (groups in time order, members
// sorted by name, no times) are equal.
#pragma once

#include <string>
#include <vector>

#include "railcrash/dae_system.hpp"

namespace railcrash {

/// [s] Default window within which outcome events form one group (see the header comment).
constexpr double kBranchWindow = 1e-4;

/// One discrete outcome: the first time `element` did `what` ("fracture", "override", ...).
struct OutcomeEvent {
  double t = 0.0;  // [s] located time
  std::string element;
  std::string what;
};

struct OutcomeSignature {
  std::vector<OutcomeEvent> events;  // in time order
  double window = kBranchWindow;     // [s] grouping window used by order()

  /// With times: "car1_draft_gear:fracture@15.307ms>car2_draft_gear:fracture@15.348ms"
  /// ("none" when there is no outcome).
  std::string text() const;
  /// Order only, groups within the window as sorted sets:
  /// "car1_draft_gear:fracture+car2_draft_gear:fracture>couplers:vertical overlap lost" ("none").
  std::string order() const;
  /// JSON object {"signature": text, "branch": order, "events": [{t, element, what}, ...]}.
  std::string json() const;
};

/// The outcome name of one event text ("fracture", ...), or "" when it is not an outcome. For
/// a text that joins several changes, the outcomes it holds, joined by ", ".
std::string outcome_of_event(const std::string& what);

/// The signature of a run's events (every committed mode change, in order).
OutcomeSignature outcome_signature(const std::vector<EventRecord>& events, double window = kBranchWindow);

/// Whether two runs are on the same branch (equal order-only forms).
bool same_branch(const OutcomeSignature& a, const OutcomeSignature& b);

}  // namespace railcrash
