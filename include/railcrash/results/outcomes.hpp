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
// Which outcomes, not their interleaving. By default two runs are on the same branch when the
// same elements reach the same outcomes (the sets are equal), whatever the order between
// different elements. Each element's own outcomes come in a fixed physical order (a draft gear
// bottoms, its pin shears, it goes solid, it fractures), so the set fixes each element's
// sequence; what it leaves out is the interleaving of different elements, which moves
// continuously with the parameters without a jump in the responses: in the report's study
// run 0's two gears reach each stage 3 to 52 us apart, a 20 % change of P7 moves their
// fractures from 41 to 106 us apart, and with order-sensitive branches the bisections of such
// order-only changes found jumps of 0.012 or less in R2, the size of its numerical noise. A
// response jumps where an outcome appears or disappears (one gear fractures instead of two).
//
// Order, when asked (a window, e.g. 0.1 ms): outcomes closer in time than the window (each
// within the window of the previous one) form one group compared as a set, and the groups
// must come in the same order.
//
// The order-only form lists the groups in time order, members sorted by name, no times; two
// runs are on the same branch when their order-only forms are equal.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "railcrash/solver/dae_system.hpp"

namespace railcrash {

/// [s] Default window within which outcome events form one group: all of them (the set of
/// outcomes, order aside; see the header comment).
constexpr double kBranchWindow = std::numeric_limits<double>::infinity();

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
  /// Order only, groups within the window as sorted sets (with the default window, one group:
  /// the set): "car1_draft_gear:fracture+car2_draft_gear:fracture>couplers:vertical overlap lost"
  /// with a window of 0.1 ms ("none" when there is no outcome).
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
