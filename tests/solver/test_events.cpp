// The event layer on its own (events.hpp, event_loop.hpp): the locator against an analytic
// step interpolant, the mode tracker's boundary bookkeeping and commits, the loop over a
// step's crossings with a handler that goes on across them or restarts.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "railcrash/solver/event_loop.hpp"
#include "railcrash/solver/events.hpp"
#include "support.hpp"

using namespace railcrash;

namespace {

// A ball (point mass with inertia) and a circular obstacle of radius 1 centred at the origin:
// while the contact is open its root is the ball's distance from the circle, x - 1 on the x axis.
Model ball_and_circle(double x0, double vx) {
  return testing::model_from_text(
      "railcrash: 1\nname: ball\nunits: SI\ngravity: [0, 0]\nbodies:\n"
      "  - {name: ball, mass: 2, inertia: 0.1, position: [" + std::to_string(x0) + ", 0], velocity: [" + std::to_string(vx) + ", 0]}\nelements:\n"
      "  - {name: bump, type: contact, circle_center: [0, 0], circle_radius: 1, stiffness: 1.0e6, "
      "points: [{body: ball, at: [0, 0]}]}\nsimulation: {t_end: 1}\n");
}

/// x(t) = 2 - t^2 on [0, 1.2] (the ball reaches the circle, x = 1, at t = 1 exactly), y = 0,
/// theta = 0; rates from the same formula. Counts its whole-state evaluations.
class ParabolaStep final : public StepInterpolant {
 public:
  explicit ParabolaStep(int size) : y_(static_cast<std::size_t>(size), 0.0) {}
  double t0() const override { return 0.0; }
  double t1() const override { return 1.2; }
  bool dense() const override { return true; }
  const double* state_at(double t) override {
    ++whole_states;
    fill(t, y_.data());
    return y_.data();
  }
  void unknowns_at(const std::vector<int>& unknowns, double t, double* y) override {
    std::vector<double> all(y_.size(), 0.0);
    fill(t, all.data());
    for (const int i : unknowns) y[i] = all[static_cast<std::size_t>(i)];
  }
  void rates_at(double t, double* yp) override {
    for (std::size_t i = 0; i < y_.size(); ++i) yp[i] = 0.0;
    yp[0] = -2.0 * t;  // x'
    yp[3] = -2.0;      // vx'
  }
  int whole_states = 0;

 private:
  static void fill(double t, double* y) {
    y[0] = 2.0 - t * t;  // x
    y[1] = 0.0;          // y
    y[2] = 0.0;          // theta
    y[3] = -2.0 * t;     // vx
    y[4] = 0.0;
    y[5] = 0.0;
  }
  std::vector<double> y_;
};

}  // namespace

TEST_CASE("the event locator finds the crossing of an analytic interpolant to the stated tolerance", "[events]") {
  const Model model = ball_and_circle(2.0, -1.0);
  DaeSystem system(model);
  REQUIRE(system.size() == 6);
  REQUIRE(system.root_count() >= 1);
  ParabolaStep step(system.size());
  EventLocator locator(system);
  // The open contact's root is the distance from the circle: x - 1.
  CHECK(locator.root_at(step, 0, 0, 0.0) == Approx(1.0));
  CHECK(locator.root_at(step, 0, 0, 0.5) == Approx(0.75));
  CHECK(locator.root_at(step, 0, 0, 1.2) == Approx(-0.44));
  CHECK(step.whole_states == 0);  // only the element's unknowns were interpolated

  const double tolerance = 1e-12;
  const double t = locator.locate(step, 0, 0, 0.0, 1.0, 1.2, -0.44, tolerance);
  // The earliest time the root reaches zero, from the side where it is at or below zero.
  CHECK(t >= 1.0);
  CHECK(t - 1.0 <= tolerance);
  CHECK(locator.root_at(step, 0, 0, t) <= 0.0);

  // Through the queue: located, then the whole state there, at or below zero.
  locator.queue() = {Crossing{1.2, 0, 0, 0}};
  locator.locate_queue(step, {1.0, 1.0, 1.0}, {-0.44, 1.0, 1.0}, tolerance);
  REQUIRE(locator.queue().size() == 1);
  Crossing c = locator.queue().front();
  CHECK(std::abs(c.t - 1.0) <= tolerance);
  const double* y_event = locator.event_state(step, c, tolerance);
  CHECK(c.t >= 1.0);
  CHECK(c.t - 1.0 <= 2.0 * tolerance);
  CHECK(y_event[0] == Approx(1.0).margin(1e-11));
  CHECK(y_event[0] <= 1.0);  // the root at the event state: at or below zero
}

TEST_CASE("the event locator keeps the queue in time order and finds crossings at a step's end alone", "[events]") {
  const Model model = ball_and_circle(2.0, -1.0);
  DaeSystem system(model);
  EventLocator locator(system);
  locator.queue() = {Crossing{0.3, 0, 0, 0}, Crossing{0.7, 0, 1, 0}};
  locator.insert_after(0, Crossing{0.5, 0, 2, 1});
  locator.insert_after(0, Crossing{0.9, 0, 2, 1});
  REQUIRE(locator.queue().size() == 4);
  CHECK(locator.queue()[0].t == 0.3);
  CHECK(locator.queue()[1].t == 0.5);
  CHECK(locator.queue()[2].t == 0.7);
  CHECK(locator.queue()[3].t == 0.9);

  // Euler's rule: a fall from >= 0 to < 0 is -1, a rise from < 0 to >= 0 is +1.
  std::vector<int> direction(4, 7);
  CHECK(EventLocator::step_end_crossings({0.0, 1.0, -1.0, -1.0}, {-1e-300, 2.0, 0.0, -2.0}, direction));
  CHECK(direction == std::vector<int>{-1, 0, 1, 0});
  CHECK_FALSE(EventLocator::step_end_crossings({1.0}, {0.5}, direction));
  CHECK(direction[0] == 0);
}

TEST_CASE("the mode tracker carries a root at zero as on its boundary, commits a crossing and counts it", "[events]") {
  // The ball starts at rest exactly on the circle (open, root 0): armed as +0, on its boundary.
  const Model model = ball_and_circle(1.0, 0.0);
  DaeSystem system(model);
  std::vector<double> y = system.initial_state();
  ModeTracker modes(system, std::vector<double>(static_cast<std::size_t>(system.size()), 1e-9));
  modes.arm(0.0, y.data());
  CHECK(modes.on_boundary(0));
  CHECK(modes.previous()[0] == std::numeric_limits<double>::min());
  CHECK_FALSE(modes.on_boundary(1));

  // Below zero by round-off only: resting on the boundary, no crossing.
  std::vector<Crossing> crossings;
  y[0] = 1.0 - 1e-17;
  system.roots(0.0, y.data(), modes.now().data());
  REQUIRE(modes.now()[0] <= 0.0);
  modes.scan(0.0, y.data(), crossings);
  CHECK(crossings.empty());
  CHECK(modes.on_boundary(0));
  CHECK(modes.now()[0] == std::numeric_limits<double>::min());

  // Clearly below: one crossing of element 0's root 0, at the step's end.
  modes.end_step();
  y[0] = 0.99;
  system.roots(0.1, y.data(), modes.now().data());
  modes.scan(0.1, y.data(), crossings);
  REQUIRE(crossings.size() == 1);
  CHECK(crossings[0].element == 0);
  CHECK(crossings[0].local == 0);
  CHECK(crossings[0].t == 0.1);
  CHECK(crossings[0].generation == 0);

  // The commit: the contact closes (its root is now the penetration, 0.01), counted once at t.
  modes.begin_step();
  std::vector<EventRecord> events;
  const ElementStates::Snapshot before = system.modes().snapshot();
  CHECK(modes.commit(0, 0, 0.05, y.data(), events));
  REQUIRE(events.size() == 1);
  CHECK(events[0].t == 0.05);
  CHECK(events[0].element == "bump");
  CHECK_FALSE(modes.on_boundary(0));  // a new mode: ordinary roots again
  CHECK(modes.changes_of(0) == 1);
  CHECK(modes.changed_elements() == std::vector<int>{0});
  CHECK(modes.changed_at(0.05) == std::vector<char>{1});
  CHECK(modes.changed_at(0.04) == std::vector<char>{0});
  std::vector<double> g(static_cast<std::size_t>(system.root_count()));
  system.roots(0.1, y.data(), g.data());
  CHECK(g[0] == Approx(0.01));
  modes.record_change(0, 0.07);
  CHECK(modes.changes_of(0) == 2);
  CHECK(modes.changed_at(0.05) == std::vector<char>{0});
  CHECK(modes.changed_at(0.07) == std::vector<char>{1});
  // A new step forgets the changes; the system's modes go back with a snapshot.
  modes.begin_step();
  CHECK(modes.changes_of(0) == 0);
  modes.restore(before);
  system.roots(0.1, y.data(), g.data());
  CHECK(g[0] == Approx(-0.01));  // open again: the distance from the circle
}

namespace {

// Whether a DaeSystem has a member reset_modes() (issue 37 item 5: it must not).
template <class System, class = void>
struct HasResetModes : std::false_type {};
template <class System>
struct HasResetModes<System, std::void_t<decltype(std::declval<System&>().reset_modes())>> : std::true_type {};

}  // namespace

TEST_CASE("the DaeSystem only reads the element modes and every write goes through a ModeTracker", "[events]") {
  // A non-const system gives its modes read-only and has no reset of them (at e8c6869 modes()
  // gave them writable and reset_modes() was the system's: this does not compile there).
  static_assert(std::is_same_v<decltype(std::declval<DaeSystem&>().modes()), const ElementStates&>);
  static_assert(!HasResetModes<DaeSystem>::value);
  static_assert(HasResetModes<ModeTracker>::value);

  // The ball starts on the circle (open); at x = 0.99 the open contact's root, x - 1, is -0.01.
  const Model model = ball_and_circle(1.0, 0.0);
  DaeSystem system(model);
  std::vector<double> y = system.initial_state();
  y[0] = 0.99;
  std::vector<double> g(static_cast<std::size_t>(system.root_count()));
  system.roots(0.0, y.data(), g.data());
  REQUIRE(g[0] == Approx(-0.01));
  // One tracker commits the closing, another (the settle's, a second run's) resets and restores:
  // the system's evaluations follow every write, whichever tracker made it.
  ModeTracker run(system);
  std::vector<EventRecord> events;
  REQUIRE(run.commit(0, 0, 0.0, y.data(), events));
  const ElementStates::Snapshot closed = run.snapshot();
  system.roots(0.0, y.data(), g.data());
  CHECK(g[0] == Approx(0.01));  // closed: the penetration
  ModeTracker other(system);
  other.reset_modes();
  system.roots(0.0, y.data(), g.data());
  CHECK(g[0] == Approx(-0.01));  // open again: the start mode
  CHECK(&run.modes() == &other.modes());
  CHECK(&system.modes() == &std::as_const(run).modes());
  other.restore(closed);
  system.roots(0.0, y.data(), g.data());
  CHECK(g[0] == Approx(0.01));
}

namespace {

/// Records what the event loop asks; goes on across every change or none.
class RecordingHandler final : public EventHandler {
 public:
  explicit RecordingHandler(bool go_on) : go_on_(go_on) {}
  void before_change(const Crossing& c, const double* y_at_event) override {
    before_times.push_back(c.t);
    x_at_event.push_back(y_at_event[0]);
  }
  void committed(const Crossing& /*c*/) override { ++commits; }
  bool goes_on_across(const Crossing& /*c*/, const double* /*y_at_event*/, const std::vector<EventRecord>& events) override {
    reported += static_cast<int>(events.size());  // (records it was asked about)
    return go_on_;
  }
  void restart_at(const Crossing& c, const double* /*y_at_event*/) override { restart_times.push_back(c.t); }
  std::vector<double> before_times, x_at_event, restart_times;
  int commits = 0, reported = 0;

 private:
  bool go_on_;
};

}  // namespace

TEST_CASE("the event loop commits a located crossing and goes on across it or restarts there", "[events]") {
  const double tolerance = 1e-12;
  for (const bool go_on : {true, false}) {
    const Model model = ball_and_circle(2.0, -1.0);
    DaeSystem system(model);
    ParabolaStep step(system.size());
    ModeTracker modes(system);
    EventLocator locator(system);
    std::vector<double> y_start(static_cast<std::size_t>(system.size()));
    std::copy(step.state_at(0.0), step.state_at(0.0) + system.size(), y_start.begin());
    modes.arm(0.0, y_start.data());
    std::vector<double> y_end(static_cast<std::size_t>(system.size()));
    std::copy(step.state_at(1.2), step.state_at(1.2) + system.size(), y_end.begin());
    system.roots(1.2, y_end.data(), modes.now().data());
    modes.scan(1.2, y_end.data(), locator.queue());
    REQUIRE(locator.queue().size() == 1);
    locator.locate_queue(step, modes.previous(), modes.now(), tolerance);
    RecordingHandler handler(go_on);
    std::vector<EventRecord> events;
    const bool restarted = commit_crossings(step, y_end.data(), modes, locator, handler, tolerance, events);
    CHECK(restarted == !go_on);
    // One change: the contact closes where x(t) = 2 - t^2 reaches the circle, t = 1.
    REQUIRE(handler.before_times.size() == 1);
    CHECK(std::abs(handler.before_times[0] - 1.0) <= 2.0 * tolerance);
    CHECK(handler.x_at_event[0] <= 1.0);
    CHECK(handler.x_at_event[0] == Approx(1.0).margin(1e-11));
    CHECK(handler.commits == 1);
    CHECK(handler.reported == 1);  // asked once, with the change's one record
    REQUIRE(events.size() == 1);
    CHECK(events[0].element == "bump");
    CHECK(modes.changes_of(0) == 1);
    if (go_on) {
      // The step stands: its end's roots, refreshed in the new (contact) mode, start the next
      // step: the penetration at x = 0.56, 0.44.
      CHECK(handler.restart_times.empty());
      CHECK(modes.previous()[0] == Approx(0.44));
    } else {
      REQUIRE(handler.restart_times.size() == 1);
      CHECK(handler.restart_times[0] == handler.before_times[0]);
    }
  }
}

namespace {

/// A step known at its end alone (explicit Euler's): the state at t1 = 0.1, whatever t.
class StepEndOnly final : public StepInterpolant {
 public:
  explicit StepEndOnly(std::vector<double> y_end) : y_(std::move(y_end)) {}
  double t0() const override { return 0.0; }
  double t1() const override { return 0.1; }
  bool dense() const override { return false; }
  const double* state_at(double /*t*/) override { return y_.data(); }
  void unknowns_at(const std::vector<int>& unknowns, double /*t*/, double* y) override {
    for (const int i : unknowns) y[i] = y_[static_cast<std::size_t>(i)];
  }
  void rates_at(double /*t*/, double* yp) override { std::fill(yp, yp + y_.size(), 0.0); }

 private:
  std::vector<double> y_;
};

}  // namespace

TEST_CASE("the event loop commits a step known at its end alone there, all at once, and restarts once", "[events]") {
  // The ball starts at x = 2 (open contact, root x - 1 = 1) and ends the step at x = 0.99,
  // inside the circle: its root fell to -0.01 and the contact closes at the step's end, t1.
  const Model model = ball_and_circle(2.0, -1.0);
  DaeSystem system(model);
  ModeTracker modes(system);
  EventLocator locator(system);
  std::vector<double> y_start = system.initial_state();
  system.roots(0.0, y_start.data(), modes.previous().data());
  std::vector<double> y_end = y_start;
  y_end[0] = 0.99;
  system.roots(0.1, y_end.data(), modes.now().data());
  REQUIRE(modes.now()[0] == Approx(-0.01));
  REQUIRE(locator.queue_step_end_crossings(0.1, modes.previous(), modes.now()));
  REQUIRE(locator.queue().size() == 1);
  CHECK(locator.queue()[0].t == 0.1);
  CHECK(locator.queue()[0].element == 0);
  CHECK(locator.queue()[0].local == 0);
  CHECK(locator.queue()[0].direction == -1);

  StepEndOnly step(y_end);
  RecordingHandler handler(false);
  std::vector<EventRecord> events;
  CHECK(commit_crossings(step, step.state_at(0.1), modes, locator, handler, 0.0, events));
  CHECK(handler.before_times == std::vector<double>{0.1});  // the old modes, seen once at t1
  CHECK(handler.x_at_event == std::vector<double>{0.99});
  CHECK(handler.commits == 1);
  CHECK(handler.reported == 0);  // never asked to go on across: the step's end is all there is
  CHECK(handler.restart_times == std::vector<double>{0.1});
  REQUIRE(events.size() == 1);
  CHECK(events[0].t == 0.1);
  CHECK(events[0].element == "bump");
  // The step is done (now() became previous()); the contact is closed: its root is the
  // penetration, 0.01.
  std::vector<double> g(static_cast<std::size_t>(system.root_count()));
  system.roots(0.1, y_end.data(), g.data());
  CHECK(g[0] == Approx(0.01));

  // Nothing fired: no queue (the caller ends the step itself).
  CHECK_FALSE(locator.queue_step_end_crossings(0.2, g, g));
  CHECK(locator.queue().empty());
}
