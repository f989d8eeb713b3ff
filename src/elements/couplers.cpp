#include "railcrash/elements/couplers.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <string>

#include "railcrash/core/error.hpp"

namespace railcrash {

namespace {

const char* side_name(int side) { return side > 0 ? "buff" : "draft"; }

/// Text for events.csv of a change of an AxialHysteresis; `segment_names` gives the names of
/// entering segment 1 and leaving it (nullptr: "curve segment n").
std::string describe(AxialHysteresis::Change change, const AxialHysteresis::State& st, const AxialHysteresis& law,
                     const char* const* segment_names = nullptr) {
  using C = AxialHysteresis::Change;
  const std::string side = std::string(" (") + side_name(st.side) + ")";
  switch (change) {
    case C::Engaged: return "slack taken up" + side;
    case C::Sliding: return "sliding" + side;
    case C::Reversal: return "reversal" + side;
    case C::OnLowerCurve: return "unloading" + side;
    case C::Reloading: return "reloading" + side;
    case C::OnUpperCurve: return "back on the loading curve" + side;
    case C::Released: return "released" + side;
    case C::Centre: return law.preloaded() ? "neutral" : "in the slack";
    case C::SideChange: return std::string("through zero force to ") + side_name(st.side);
    case C::SegmentUp:
    case C::SegmentDown: break;
  }
  if (segment_names) return segment_names[change == C::SegmentUp ? 0 : 1] + side;
  return "curve segment " + std::to_string(st.segment + 1) + side;
}

/// Commits root `index` of an element whose roots are all positive inside its mode: applies
/// its change (apply(i, event)), then the changes of roots that are already negative in the
/// new mode (crossings that coincided, or an Euler step that went past several), a few at
/// most, joining their names.
template <int N, class Roots, class Apply>
bool commit_crossing(int index, int direction, Roots roots, Apply apply, Element::Event& event) {
  if (direction > 0) return false;  // every root is positive inside its mode
  std::array<double, N> g{};
  roots(g.data());
  if (g[static_cast<std::size_t>(index)] > 0.0) return false;  // not crossed in the current mode
  apply(index, event);
  for (int pass = 0; pass < 8; ++pass) {
    roots(g.data());
    const auto next = std::find_if(g.begin(), g.end(), [](double value) { return value < 0.0; });
    if (next == g.end()) break;
    Element::Event more;
    apply(static_cast<int>(next - g.begin()), more);
    event.what += ", " + more.what;
    if (more.kind == Element::EventKind::Jump) event.kind = Element::EventKind::Jump;  // a chain is a kink only if all are
  }
  return true;
}

/// Which way the faces of a two-point element meet along global x: the side of P2 relative
/// to P1 at the start (by the points, or by the bodies' centres when the points are level).
double facing_side(const Element& e, const ElementState<double>& s) {
  const double dx = point_offset(e, s).d.x;
  if (dx != 0.0) return dx > 0.0 ? 1.0 : -1.0;
  const double centres = s.q[static_cast<std::size_t>(e.point_slot(1))].x - s.q[static_cast<std::size_t>(e.point_slot(0))].x;
  return centres < 0.0 ? -1.0 : 1.0;
}

/// A force-deflection table [[deflection, force], ...] starting at [0, 0], deflections
/// strictly increasing, forces not negative.
void read_curve(ParameterReader& p, const std::string& key, const std::vector<std::vector<double>>& table,
                std::vector<double>& x, std::vector<double>& y) {
  if (table.size() < 2) p.fail(key, "'" + key + "' needs at least two points [[deflection, force], ...]");
  if (table[0][0] != 0.0 || table[0][1] != 0.0)
    p.fail(key, "'" + key + "' must start at [0, 0] (deflection beyond the slack, force)");
  for (std::size_t k = 0; k < table.size(); ++k) {
    if (k > 0 && !(table[k][0] > table[k - 1][0]))
      p.fail(key, "'" + key + "' point " + std::to_string(k + 1) + ": deflections must increase strictly");
    if (table[k][1] < 0.0) p.fail(key, "'" + key + "' point " + std::to_string(k + 1) + ": force must not be negative");
    x.push_back(table[k][0]);
    y.push_back(table[k][1]);
  }
}

}  // namespace

// ---- PiecewiseLinear ----------------------------------------------------------------------

PiecewiseLinear PiecewiseLinear::through(const std::vector<double>& x, const std::vector<double>& y) {
  PiecewiseLinear c;
  for (std::size_t k = 0; k + 1 < x.size(); ++k) {
    c.start.push_back(x[k]);
    c.value.push_back(y[k]);
    c.slope.push_back((y[k + 1] - y[k]) / (x[k + 1] - x[k]));
  }
  return c;
}

int PiecewiseLinear::segment_of(double x) const {
  int j = 0;
  while (j + 1 < segments() && x >= start[static_cast<std::size_t>(j + 1)]) ++j;
  return j;
}

double PiecewiseLinear::max_slope() const { return *std::max_element(slope.begin(), slope.end()); }

// ---- AxialHysteresis ------------------------------------------------------------------------

void AxialHysteresis::roots(const State& st, double u, double rate, double* g) const {
  std::fill(g, g + kRoots, 1.0);
  const double x = side_deflection(st, u);
  const double x_rate = st.side * rate;
  const double kt = transition_stiffness;
  const auto segment_ends = [&](int j) {
    if (j > 0) g[2] = x - upper.start[static_cast<std::size_t>(j)] + tolerance;
    if (j + 1 < upper.segments()) g[3] = upper.start[static_cast<std::size_t>(j + 1)] - x + tolerance;
  };
  switch (st.mode) {
    case Mode::Open:
      g[0] = 0.5 * slack - u + tolerance;
      g[1] = 0.5 * slack + u + tolerance;
      break;
    case Mode::Neutral:
      g[0] = upper.at(std::max(u, 0.0)) - kt * u;
      g[1] = upper.at(std::max(-u, 0.0)) + kt * u;
      break;
    case Mode::Loading:
      g[0] = x_rate;
      segment_ends(st.segment);
      break;
    case Mode::Transition: {
      // Leaves where the line rejoins U going up, or meets Lw / zero force going down: past
      // the boundary AND moving that way (hybrid.hpp). Without the rate a gear resting on its
      // reversal point chattered between loading and transition there (x crept 1e-14 past it
      // while x' < 0): 1.15 million events in emu3_unit_collision at rtol 1e-3.
      const double up = rejoin_upper(st.x0, st.f0);
      if (std::isfinite(up)) g[0] = position_root_moving_on(up - x + tolerance, x_rate);
      g[1] = position_root_moving_on(x - std::max(rejoin_lower(st.x0, st.f0), st.x0 - st.f0 / kt) + tolerance, -x_rate);
      break;
    }
    case Mode::Unloading:
      g[0] = -x_rate;
      if (lower.value[static_cast<std::size_t>(st.segment)] < 0.0) g[1] = lower.on_segment(st.segment, x);
      else if (st.segment == 0) g[1] = x + tolerance;
      segment_ends(st.segment);
      break;
    case Mode::Released:
      g[0] = -x_rate;
      g[1] = x + tolerance;
      break;
  }
}

AxialHysteresis::Change AxialHysteresis::transition(State& st, int index, double u) const {
  const double x = side_deflection(st, u);
  switch (st.mode) {
    case Mode::Open:
      return engage(st, index == 0 ? 1 : -1, u);
    case Mode::Neutral:
      st.side = index == 0 ? 1 : -1;
      st.mode = Mode::Loading;
      st.segment = upper.segment_of(side_deflection(st, u));
      return Change::Sliding;
    case Mode::Loading:
      if (index == 0) {
        st.f0 = upper.on_segment(st.segment, x);
        st.x0 = x;
        st.mode = Mode::Transition;
        return Change::Reversal;
      }
      break;
    case Mode::Transition:
      if (index == 0) {
        st.mode = Mode::Loading;
        st.segment = upper.segment_of(x);
        return Change::OnUpperCurve;
      }
      if (rejoin_lower(st.x0, st.f0) > st.x0 - st.f0 / transition_stiffness && x > 0.0) {
        st.mode = Mode::Unloading;
        st.segment = lower.segment_of(x);
        return Change::OnLowerCurve;
      }
      return leave_at_zero(st, u);  // zero force before the unloading curve
    case Mode::Unloading:
      if (index == 0) {
        st.f0 = lower.on_segment(st.segment, x);
        st.x0 = x;
        st.mode = Mode::Transition;
        return Change::Reloading;
      }
      if (index == 1) return leave_at_zero(st, u);
      break;
    case Mode::Released:
      if (index == 0) {
        st.mode = Mode::Transition;
        st.x0 = x;
        st.f0 = 0.0;
        return Change::Reloading;
      }
      return leave_side(st, u);
  }
  // Loading / unloading past a segment end.
  if (index == 2) {
    --st.segment;
    return Change::SegmentDown;
  }
  ++st.segment;
  return Change::SegmentUp;
}

AxialHysteresis::Change AxialHysteresis::engage(State& st, int side, double u) const {
  st = State{};
  st.side = side;
  const double x = side_deflection(st, u);
  if (preloaded()) {  // the preload builds up along the transition line
    st.mode = Mode::Transition;
    st.x0 = x;
  } else {
    st.mode = Mode::Loading;
    st.segment = upper.segment_of(x);
  }
  return Change::Engaged;
}

AxialHysteresis::Change AxialHysteresis::leave_at_zero(State& st, double u) const {
  if (side_deflection(st, u) > 0.0) {
    st.mode = Mode::Released;
    return Change::Released;
  }
  return leave_side(st, u);
}

AxialHysteresis::Change AxialHysteresis::leave_side(State& st, double u) const {
  if (preloaded() || slack > 0.0) {
    st = State{};
    st.mode = preloaded() ? Mode::Neutral : Mode::Open;
    return Change::Centre;
  }
  st.side = -st.side;
  st.mode = Mode::Loading;
  st.segment = upper.segment_of(side_deflection(st, u));
  return Change::SideChange;
}

AxialHysteresis::State AxialHysteresis::initial(double u, double rate) const {
  State st;
  const double a = std::abs(u);
  if (preloaded()) {
    const double stick = transition_stiffness * a, limit = upper.at(a);
    if (stick < limit || (stick == limit && rate * u <= 0.0)) {
      st.mode = Mode::Neutral;
      return st;
    }
    st.side = u > 0.0 ? 1 : -1;
  } else {
    if (slack > 0.0 && (a < 0.5 * slack || (a == 0.5 * slack && rate * u <= 0.0))) {  // on the edge at rest: open
      st.mode = Mode::Open;
      return st;
    }
    st.side = u > 0.0 ? 1 : (u < 0.0 ? -1 : (rate >= 0.0 ? 1 : -1));
  }
  const double x = side_deflection(st, u);
  st.segment = upper.segment_of(x);
  if (st.side * rate > 0.0) {
    st.mode = Mode::Loading;
  } else {  // loaded to here, at rest or unloading: on the transition line from the curve
    st.mode = Mode::Transition;
    st.x0 = x;
    st.f0 = upper.at(x);
  }
  return st;
}

double AxialHysteresis::energy(const State& st, double u) const {
  const double x = side_deflection(st, u);
  switch (st.mode) {
    case Mode::Neutral: return 0.5 * transition_stiffness * u * u;
    case Mode::Loading: return unload_from(x, upper.on_segment(st.segment, x));
    case Mode::Transition: return unload_from(x, st.f0 + transition_stiffness * (x - st.x0));
    case Mode::Unloading: return lower_tail(x);
    case Mode::Open:
    case Mode::Released: break;
  }
  return 0.0;
}

double AxialHysteresis::rejoin_upper(double x0, double f0) const {
  const double kt = transition_stiffness;
  for (int j = upper.segment_of(x0); j < upper.segments(); ++j) {
    const auto k = static_cast<std::size_t>(j);
    const double low = std::max(x0, upper.start[k]);
    const double high = j + 1 < upper.segments() ? upper.start[k + 1] : std::numeric_limits<double>::infinity();
    const double gap = f0 + kt * (low - x0) - upper.on_segment(j, low);  // line - U, non-decreasing in x
    if (gap >= 0.0) return low;
    const double closing = kt - upper.slope[k];
    if (closing > 0.0 && low - gap / closing <= high) return low - gap / closing;
  }
  return std::numeric_limits<double>::infinity();
}

double AxialHysteresis::rejoin_lower(double x0, double f0) const {
  const double kt = transition_stiffness;
  for (int j = lower.segment_of(x0); j >= 0; --j) {
    const auto k = static_cast<std::size_t>(j);
    const double high = j + 1 < lower.segments() ? std::min(x0, lower.start[k + 1]) : x0;
    const double low = j > 0 ? lower.start[k] : -std::numeric_limits<double>::infinity();
    const double gap = f0 + kt * (high - x0) - lower.on_segment(j, high);  // line - Lw, non-decreasing in x
    if (gap <= 0.0) return high;
    const double closing = kt - lower.slope[k];
    if (closing > 0.0 && high - gap / closing >= low) return high - gap / closing;
  }
  return -std::numeric_limits<double>::infinity();
}

double AxialHysteresis::unload_from(double x, double force) const {
  if (force <= 0.0) return 0.0;
  const double meet = rejoin_lower(x, force);
  if (meet <= x - force / transition_stiffness)  // the line reaches zero force before Lw
    return 0.5 * force * force / transition_stiffness;
  return 0.5 * (force + lower.at(meet)) * (x - meet) + lower_tail(meet);
}

double AxialHysteresis::lower_tail(double x) const {
  double total = 0.0, high = x;
  for (int j = lower.segment_of(x); j >= 0 && high > 0.0; --j) {
    const auto k = static_cast<std::size_t>(j);
    const double f_high = lower.on_segment(j, high);
    if (f_high <= 0.0) break;
    const double low = j > 0 ? lower.start[k] : 0.0;
    const double f_low = lower.on_segment(j, low);
    if (f_low <= 0.0) {  // Lw reaches zero inside the segment
      total += 0.5 * f_high * f_high / lower.slope[k];
      break;
    }
    total += 0.5 * (f_low + f_high) * (high - low);
    high = low;
  }
  return total;
}

// ---- DeadBand ---------------------------------------------------------------------------------

void DeadBand::roots(Mode m, double z, double* g) const {
  g[0] = g[1] = 1.0;
  switch (m) {
    case Mode::Below: g[0] = lo - z + tolerance; break;
    case Mode::Above: g[1] = z - hi + tolerance; break;
    case Mode::Inside:
      if (below_active) g[0] = z - lo + tolerance;
      if (above_active) g[1] = hi - z + tolerance;
      break;
  }
}

DeadBand::Mode DeadBand::transition(Mode m, int index) const {
  const bool straight = lo == hi && below_active && above_active;  // no band: one line
  if (m == Mode::Inside) return index == 0 ? Mode::Below : Mode::Above;
  if (m == Mode::Below) return straight ? Mode::Above : Mode::Inside;
  return straight ? Mode::Below : Mode::Inside;
}

DeadBand::Mode DeadBand::initial(double z, double rate) const {
  if (below_active && (z < lo || (z == lo && rate < 0.0))) return Mode::Below;
  if (above_active && (z > hi || (z == hi && rate > 0.0))) return Mode::Above;
  if (lo == hi && below_active && above_active) return rate < 0.0 ? Mode::Below : Mode::Above;
  return Mode::Inside;
}

double DeadBand::energy(Mode m, double z) const {
  if (m == Mode::Inside || !(stiffness > 0.0)) return 0.0;
  const double f = force(m, z);
  return 0.5 * f * f / stiffness;
}

// ---- draft_gear ------------------------------------------------------------------------------

namespace {
constexpr int kPinRoot = AxialHysteresis::kRoots;
constexpr int kFractureRoot = AxialHysteresis::kRoots + 1;
const char* const kGearSegments[] = {"bottomed", "off bottom"};
}  // namespace

DraftGear::DraftGear(ElementSpec& spec) : HybridElement(spec.name, spec.type, spec.points, spec.where) {
  ParameterReader& p = *spec.parameters;
  initial_stiffness = p.value("initial_stiffness");
  travel = p.value("travel");
  stiffness_after_bottoming = p.value("stiffness_after_bottoming");
  hysteresis_load = p.value("hysteresis_load");
  pin_shear_load = p.number("pin_shear_load");
  const auto post_shear = p.number("post_shear_travel");
  fracture_load = p.number("fracture_load");
  const auto transition = p.number("transition_stiffness");
  free_length = p.number("free_length");
  if (post_shear && !pin_shear_load)
    p.fail("post_shear_travel", "'post_shear_travel' is the travel after the shear pin fails: give 'pin_shear_load' too");
  post_shear_travel = post_shear.value_or(0.0);
  transition_stiffness = transition.value_or(stiffness_after_bottoming);
  const double steepest = std::max(initial_stiffness, stiffness_after_bottoming);
  if (transition_stiffness < steepest || !(transition_stiffness > initial_stiffness))
    p.fail(transition ? "transition_stiffness" : "stiffness_after_bottoming",
           "the transition stiffness (default: stiffness_after_bottoming) must exceed initial_stiffness and be at least "
           "stiffness_after_bottoming, so that the elastic line between the loading and unloading branches meets them; "
           "give a larger 'transition_stiffness'");
  const double k = initial_stiffness, h = hysteresis_load;
  law_.upper = {{0.0, travel}, {h, k * travel + h}, {k, stiffness_after_bottoming}};
  law_.lower = {{0.0, travel}, {-h, k * travel - h}, {k, stiffness_after_bottoming}};
  law_.transition_stiffness = transition_stiffness;
  law_.tolerance = kRootBand * travel;
}

DraftGear::Kinematics DraftGear::kinematics(const ElementState<double>& s) const {
  return kinematics_of(line_geometry(*this, s));
}

DraftGear::Kinematics DraftGear::kinematics_of(const LineGeometry<double>& g) const {
  return {*free_length - g.length, -dot(g.d, g.d_rate) / g.length};
}

void DraftGear::initialize(const ElementState<double>& initial) {
  require_direction(*this, initial);
  points_meet_.initialize(*this, initial);
  if (!free_length) free_length = line_geometry(*this, initial).length;
  const Kinematics k = kinematics(initial);
  State& st = initial_state_;
  st = State{};
  st.law = law_.initial(k.d, k.rate);
  const double force = std::abs(gear_force(st, k.d));
  const auto reject = [&](const char* what, double limit) {
    std::ostringstream msg;
    msg << where().prefix() << "draft_gear '" << name() << "' starts with a force " << force << " at or above its " << what
        << " " << limit << "; start it closer to its free_length";
    throw InputError(msg.str());
  };
  if (pin_shear_load && gear_force(st, k.d) >= *pin_shear_load) reject("pin_shear_load", *pin_shear_load);
  if (fracture_load && force >= *fracture_load) reject("fracture_load", *fracture_load);
}

void DraftGear::roots_at(const State& st, const Kinematics& k, double* g) const {
  std::fill(g, g + kRoots, 1.0);
  const double force = gear_force(st, k.d);
  switch (st.stage) {
    case Stage::Intact:
      law_.roots(st.law, k.d, k.rate, g);
      if (pin_shear_load) g[kPinRoot] = *pin_shear_load - force;
      if (fracture_load) g[kFractureRoot] = *fracture_load - std::abs(force);
      break;
    case Stage::Sheared:
      g[0] = st.solid_compression - k.d;
      break;
    case Stage::Solid:
      g[1] = force;
      if (fracture_load) g[kFractureRoot] = *fracture_load - force;
      break;
    case Stage::Fractured:
      break;
  }
}

void DraftGear::roots_in(const State& st, const ElementState<double>& s, double* g) const {
  const LineGeometry<double> line = line_geometry(*this, s);  // once for the law's roots and the points-meet root
  roots_at(st, kinematics_of(line), g);
  if (carries_force(st.stage)) g[kPointsMeetRoot] = points_meet_.gap(*this, s, *free_length, line.d, line.length);
}

void DraftGear::apply(State& st, int index, const Kinematics& k, Event& event) const {
  const double force = gear_force(st, k.d);
  if (index == kFractureRoot) {
    st.stage = Stage::Fractured;
    event = {"fracture", std::abs(force)};
    return;
  }
  switch (st.stage) {
    case Stage::Intact:
      if (index == kPinRoot) {
        // The pin lets go: the stored energy of the gear is lost, the coupler slides freely.
        st.solid_compression = k.d + post_shear_travel;
        st.stage = (post_shear_travel > 0.0 || k.rate <= 0.0) ? Stage::Sheared : Stage::Solid;
        event = {"pin shear", force};
        return;
      }
      // The hysteresis law's transitions keep the force continuous (elastic lines join the
      // loading and unloading lines); going solid and off solid start and end at zero force.
      event = {describe(law_.transition(st.law, index, k.d), st.law, law_, kGearSegments), k.d, EventKind::Kink};
      return;
    case Stage::Sheared:
      st.stage = Stage::Solid;
      event = {"solid", k.d, EventKind::Kink};
      return;
    case Stage::Solid:
      st.stage = Stage::Sheared;
      event = {"off solid", k.d, EventKind::Kink};
      return;
    case Stage::Fractured:
      return;
  }
}

bool DraftGear::commit_in(State& st, int index, int direction, double t, const ElementState<double>& s,
                          Event& event) const {
  // Checked whatever root fired: a step known at its end alone (Euler's) commits one root per
  // element, and the step that carries P2 past P1 may cross another of the gear's roots first.
  if (carries_force(st.stage) && points_meet_.met(*this, s, *free_length, index, kPointsMeetRoot, direction))
    points_meet_.stop(*this, t, s, *free_length, st.stage == Stage::Solid ? "solid after pin shear" : "intact",
                      "The gear needs a stroke it does not have: set its points farther apart (at least the compression "
                      "its law must reach), or give a stiffness_after_bottoming, pin_shear_load or fracture_load that "
                      "ends the travel first");
  if (index == kPointsMeetRoot) return false;
  const Kinematics k = kinematics(s);
  return commit_crossing<kRoots>(
      index, direction, [&](double* g) { roots_at(st, k, g); }, [&](int i, Event& e) { apply(st, i, k, e); }, event);
}

DraftGear::State DraftGear::stiffest_mode(const ElementState<double>& /*s*/) const {
  // Stiffest: the transition stiffness (>= every slope), e.g. the neutral stick line.
  State neutral{};
  neutral.law.mode = AxialHysteresis::Mode::Neutral;
  return neutral;
}

double DraftGear::potential_energy(const ElementState<double>& s) const {
  const State& st = mode_as<State>(s);
  const double d = kinematics(s).d;
  if (st.stage == Stage::Intact) return law_.energy(st.law, d);
  if (st.stage == Stage::Solid) {
    const double force = gear_force(st, d);
    return 0.5 * force * force / stiffness_after_bottoming;
  }
  return 0.0;
}

void DraftGear::outputs(const ElementState<double>& s, const double*, double* out) const {
  const State& st = mode_as<State>(s);
  const double d = kinematics(s).d;
  out[0] = gear_force(st, d);
  out[1] = d;
}

// ---- coupler_end -------------------------------------------------------------------------

CouplerEnd::CouplerEnd(ElementSpec& spec) : HybridElement(spec.name, spec.type, spec.points, spec.where) {
  ParameterReader& p = *spec.parameters;
  const auto stiffness = p.vector("horizontal_stiffness", 2);
  const auto lengths = p.vector("free_length", 2);
  const auto heights = p.vector("coupler_height", 2);
  total_horizontal_slack = p.value("total_horizontal_slack");
  friction = p.value("friction");
  friction_velocity = p.value("friction_velocity");
  coupled = *p.flag("coupled");
  restitution = p.value("restitution");
  shear_load = p.number("shear_load");
  if (restitution < 1.0 && coupled)
    p.fail("restitution",
           "'restitution' below 1 gives the faces a permanent set in buff, which the coupled knuckles' draft law does not "
           "follow: use it with uncoupled faces ('coupled: false') or leave it out");
  // Required and range-checked by the reader: [end K, end L].
  const auto per_end = [](const std::optional<std::vector<double>>& values) {
    return std::array<double, 2>{(*values)[0], (*values)[1]};
  };
  horizontal_stiffness = per_end(stiffness);
  free_length = per_end(lengths);
  coupler_height = per_end(heights);
  if (total_horizontal_slack > 0.0 && !coupled)
    p.fail("total_horizontal_slack",
           "'total_horizontal_slack' is the free play of coupled knuckles between buff and draft contact; uncoupled "
           "faces touch at their geometric gap: set 'coupled: true' or remove it");
  faces_.lo = free_length[0] + free_length[1];
  faces_.hi = faces_.lo + total_horizontal_slack;
  faces_.stiffness = horizontal_stiffness[0] * horizontal_stiffness[1] / (horizontal_stiffness[0] + horizontal_stiffness[1]);
  faces_.above_active = coupled;
  faces_.tolerance = kRootBand * std::max({faces_.hi, coupler_height[0], coupler_height[1]});
}

CouplerEnd::Kinematics CouplerEnd::kinematics(const ElementState<double>& s) const {
  const PointOffset<double> o = point_offset(*this, s);
  return {side_ * o.d.x, side_ * o.d_rate.x, o.d.y, o.d_rate.y};
}

void CouplerEnd::initialize(const ElementState<double>& initial) {
  side_ = facing_side(*this, initial);
  const Kinematics k = kinematics(initial);
  State& st = initial_state_;
  st = State{};
  st.overlapping = std::abs(k.dy) <= half_overlap();
  if (lossy()) {
    st.band = lossy_band(st, k);
    if (st.band == DeadBand::Mode::Below && !(k.h_rate < 0.0)) {  // deflected, not closing: loaded to here
      st.unloading = true;
      st.peak = faces_.lo - k.h;
    }
  } else {
    st.band = faces_.initial(k.h, k.h_rate);
  }
  if (shear_load && active(st) && st.band == DeadBand::Mode::Below && -face_tension(st, k.h) >= *shear_load) {
    std::ostringstream msg;
    msg << where().prefix() << "coupler_end '" << name() << "' starts with a face force " << -face_tension(st, k.h)
        << " at or above its shear_load " << *shear_load << "; start the faces closer to touching";
    throw InputError(msg.str());
  }
}

DeadBand::Mode CouplerEnd::lossy_band(const State& st, const Kinematics& k) const {
  const double touch = faces_.lo - permanent_set(st);  // spacing at which the faces touch
  return (k.h < touch || (k.h == touch && k.h_rate < 0.0)) ? DeadBand::Mode::Below : DeadBand::Mode::Inside;
}

void CouplerEnd::lossy_roots(const State& st, const Kinematics& k, double* g) const {
  const double touch = faces_.lo - permanent_set(st), tol = faces_.tolerance;
  // The position roots are crossed only moving on (position_root_moving_on, hybrid.hpp).
  if (st.blocked) {
    g[0] = position_root_moving_on(touch - k.h + tol, k.h_rate);  // clear once apart beyond the set
    return;
  }
  if (st.band == DeadBand::Mode::Inside) {
    g[0] = position_root_moving_on(k.h - touch + tol, -k.h_rate);  // contact
  } else if (!st.unloading) {
    g[0] = -k.h_rate;  // loading while the penetration grows
  } else {
    g[0] = position_root_moving_on(touch - k.h + tol, k.h_rate);                        // separation at the set
    g[1] = position_root_moving_on(k.h - (faces_.lo - st.peak) + tol, -k.h_rate);  // back on the loading line at delta_max
  }
}

void CouplerEnd::roots_at(const State& st, const Kinematics& k, double* g) const {
  std::fill(g, g + kRoots, 1.0);
  if (st.sheared) return;
  if (st.overlapping) {
    if (lossy()) lossy_roots(st, k, g);
    else faces_.roots(st.band, k.h, g);
    g[kOverlapRoot] = half_overlap() - std::abs(k.dy) + faces_.tolerance;
  } else {
    g[kOverlapRoot] = std::abs(k.dy) - half_overlap() + faces_.tolerance;
  }
  if (shear_load && active(st) && st.band == DeadBand::Mode::Below) g[kShearRoot] = *shear_load + face_tension(st, k.h);
}

void CouplerEnd::roots_in(const State& st, const ElementState<double>& s, double* g) const { roots_at(st, kinematics(s), g); }

void CouplerEnd::apply(State& st, int index, const Kinematics& k, Event& event) const {
  if (index == kShearRoot) {
    event = {"face shear failure", -face_tension(st, k.h)};
    st.sheared = true;
    return;
  }
  if (index == kOverlapRoot) {
    if (st.overlapping) {
      if (lossy() && st.band == DeadBand::Mode::Below && !st.unloading && !st.blocked)
        st.peak = std::max(st.peak, faces_.lo - k.h);  // the set of the loading that ends here
      st.overlapping = false;
      event = {"vertical overlap lost", k.dy};
    } else {
      st.overlapping = true;
      st.unloading = false;
      st.band = lossy() ? lossy_band(st, k) : faces_.initial(k.h, k.h_rate);
      st.blocked = st.band != DeadBand::Mode::Inside;
      event = {st.blocked ? "vertical overlap regained, faces past each other" : "vertical overlap regained", k.dy};
    }
    return;
  }
  if (lossy()) {
    apply_lossy(st, index, k, event);
    return;
  }
  using M = DeadBand::Mode;
  const M before = st.band;
  st.band = faces_.transition(before, index);
  const double gap = k.h - faces_.lo;
  if (st.blocked) {
    st.blocked = st.band != M::Inside;
    event = {st.blocked ? "faces pass (blocked)" : "faces clear", gap};
    return;
  }
  const char* what = "";
  if (before == M::Inside) what = st.band == M::Below ? "contact" : "slack taken up (draft)";
  else if (before == M::Below) what = st.band == M::Inside ? "separation" : "buff to draft";
  else what = st.band == M::Inside ? "draft released" : "draft to buff";
  event = {what, gap, EventKind::Kink};  // the faces meet and part at zero force
}

void CouplerEnd::apply_lossy(State& st, int index, const Kinematics& k, Event& event) const {
  const double gap = k.h - faces_.lo;  // -delta
  if (st.blocked) {
    st.blocked = false;
    st.band = DeadBand::Mode::Inside;
    event = {"faces clear", gap, EventKind::Kink};
  } else if (st.band == DeadBand::Mode::Inside) {
    st.band = DeadBand::Mode::Below;
    st.unloading = st.peak > 0.0;  // a set face is reloaded along its unloading line
    event = {"contact", gap, EventKind::Kink};
  } else if (!st.unloading) {
    st.peak = std::max(st.peak, -gap);
    st.unloading = true;
    event = {"unloading", gap, EventKind::Kink};
  } else if (index == 0) {
    st.band = DeadBand::Mode::Inside;
    st.unloading = false;
    event = {"separation", gap, EventKind::Kink};
  } else {
    st.unloading = false;
    event = {"reloading", gap, EventKind::Kink};
  }
}

bool CouplerEnd::commit_in(State& st, int index, int direction, double, const ElementState<double>& s,
                           Event& event) const {
  const Kinematics k = kinematics(s);
  return commit_crossing<kRoots>(
      index, direction, [&](double* g) { roots_at(st, k, g); }, [&](int i, Event& e) { apply(st, i, k, e); }, event);
}

CouplerEnd::State CouplerEnd::stiffest_mode(const ElementState<double>& s) const {
  // The steeper unloading line if any.
  return State{DeadBand::Mode::Below, true, false, lossy(), mode_as<State>(s).peak, false};
}

double CouplerEnd::potential_energy(const ElementState<double>& s) const {
  const State& st = mode_as<State>(s);
  if (!active(st)) return 0.0;
  const double h = kinematics(s).h;
  if (st.band != DeadBand::Mode::Below) return faces_.energy(st.band, h);
  const double push = -face_tension(st, h);
  return 0.5 * push * push / unloading_stiffness();  // what unloading gives back (k_u = k when elastic)
}

void CouplerEnd::outputs(const ElementState<double>& s, const double*, double* out) const {
  const State& st = mode_as<State>(s);
  const Kinematics k = kinematics(s);
  const bool on = active(st);
  const double tension = on ? face_tension(st, k.h) : 0.0;
  out[0] = -tension;
  out[1] = on && friction > 0.0
               ? -friction * std::abs(tension) * std::tanh(k.dy_rate / friction_velocity)
               : 0.0;
  out[2] = k.h - faces_.lo;
}

// ---- coupling ----------------------------------------------------------------------------

Coupling::Coupling(ElementSpec& spec) : HybridElement(spec.name, spec.type, spec.points, spec.where) {
  ParameterReader& p = *spec.parameters;
  const double kind_value = p.value("kind");
  const auto curve = p.table("curve", 2);
  const auto factor = p.number("unloading_factor");
  const auto loading = p.table("loading_curve", 2);
  const auto unloading = p.table("unloading_curve", 2);
  horizontal_slack = p.value("horizontal_slack");
  vertical_slack = p.value("vertical_slack");
  vertical_stiffness = p.value("vertical_stiffness");
  misalignment = p.value("misalignment");
  friction = p.value("friction");
  friction_velocity = p.value("friction_velocity");
  const auto transition = p.number("transition_stiffness");
  free_length = p.number("free_length");

  if (kind_value != 1.0 && kind_value != 2.0)
    p.fail("kind", "'kind' must be 1 (curve + unloading_factor, report type 11) or 2 (loading_curve + unloading_curve, "
                   "report type 12)");
  kind = static_cast<int>(kind_value);
  double extent = 0.0;  // [length] largest deflection in the curves
  if (kind == 1) {
    if (loading || unloading)
      p.fail(loading ? "loading_curve" : "unloading_curve",
             "kind 1 takes one 'curve' and an 'unloading_factor'; 'loading_curve' / 'unloading_curve' are for kind: 2");
    if (!curve) p.fail("curve", "missing required parameter 'curve': the loading curve [[deflection, force], ...]");
    if (!factor) p.fail("unloading_factor", "missing required parameter 'unloading_factor' (unloading force / loading force, 0 to 1)");
    std::vector<double> x, y;
    read_curve(p, "curve", *curve, x, y);
    extent = x.back();
    law_.upper = PiecewiseLinear::through(x, y);
    for (double& value : y) value *= *factor;
    law_.lower = PiecewiseLinear::through(x, y);
  } else {
    if (curve || factor)
      p.fail(curve ? "curve" : "unloading_factor",
             "kind 2 takes 'loading_curve' and 'unloading_curve'; 'curve' / 'unloading_factor' are for kind: 1");
    if (!loading) p.fail("loading_curve", "missing required parameter 'loading_curve' [[deflection, force], ...]");
    if (!unloading) p.fail("unloading_curve", "missing required parameter 'unloading_curve' [[deflection, force], ...]");
    std::vector<double> lx, ly, ux, uy;
    read_curve(p, "loading_curve", *loading, lx, ly);
    read_curve(p, "unloading_curve", *unloading, ux, uy);
    const PiecewiseLinear up = PiecewiseLinear::through(lx, ly), down = PiecewiseLinear::through(ux, uy);
    // Both curves on the union of their breakpoints (the laws' segments are shared).
    std::vector<double> x = lx;
    x.insert(x.end(), ux.begin(), ux.end());
    std::sort(x.begin(), x.end());
    x.erase(std::unique(x.begin(), x.end()), x.end());
    extent = x.back();
    for (const double at : x)
      if (down.at(at) > up.at(at) * (1.0 + 1e-12))
        p.fail("unloading_curve", "the unloading curve must not lie above the loading curve (it does at deflection " +
                                      std::to_string(at) + ")");
    if (down.slope.back() > up.slope.back())
      p.fail("unloading_curve", "beyond the last points the unloading curve would rise above the loading curve: end it "
                                "with a slope no steeper than the loading curve's");
    const auto resample = [&](const PiecewiseLinear& c) {
      std::vector<double> y;
      for (const double at : x) y.push_back(c.at(at));
      x.push_back(x.back() + 1.0);  // one more point on the last slope
      y.push_back(c.at(x.back()));
      PiecewiseLinear out = PiecewiseLinear::through(x, y);
      x.pop_back();
      return out;
    };
    law_.upper = resample(up);
    law_.lower = resample(down);
  }
  const double steepest = std::max(law_.upper.max_slope(), law_.lower.max_slope());
  law_.transition_stiffness = transition.value_or(steepest);
  if (!(law_.transition_stiffness >= steepest) || !(law_.transition_stiffness > 0.0))
    p.fail(transition ? "transition_stiffness" : (kind == 1 ? "curve" : "loading_curve"),
           "the transition stiffness must be positive and at least the steepest slope of the curves (" +
               std::to_string(steepest) + "), so that the elastic line between them meets them");
  law_.slack = horizontal_slack;
  law_.tolerance = kRootBand * (horizontal_slack + extent);
  vertical_.tolerance = kRootBand * vertical_slack;
  vertical_.lo = -0.5 * vertical_slack;
  vertical_.hi = 0.5 * vertical_slack;
  vertical_.stiffness = vertical_stiffness;
  vertical_.below_active = vertical_.above_active = vertical_stiffness > 0.0;
}

Coupling::Kinematics Coupling::kinematics(const ElementState<double>& s) const {
  const PointOffset<double> o = point_offset(*this, s);
  return {*free_length - side_ * o.d.x, -side_ * o.d_rate.x, o.d.y + misalignment, o.d_rate.y};
}

void Coupling::initialize(const ElementState<double>& initial) {
  side_ = facing_side(*this, initial);
  if (!free_length) free_length = side_ * point_offset(*this, initial).d.x;
  const Kinematics k = kinematics(initial);
  State& st = initial_state_;
  st = State{};
  st.horizontal = law_.initial(k.u, k.u_rate);
  st.vertical = vertical_.initial(k.w, k.w_rate);
}

void Coupling::roots_at(const State& st, const Kinematics& k, double* g) const {
  law_.roots(st.horizontal, k.u, k.u_rate, g);
  vertical_.roots(st.vertical, k.w, g + AxialHysteresis::kRoots);
}

void Coupling::roots_in(const State& st, const ElementState<double>& s, double* g) const { roots_at(st, kinematics(s), g); }

void Coupling::apply(State& st, int index, const Kinematics& k, Event& event) const {
  if (index < AxialHysteresis::kRoots) {
    event = {describe(law_.transition(st.horizontal, index, k.u), st.horizontal, law_), k.u, EventKind::Kink};
    return;
  }
  using M = DeadBand::Mode;
  st.vertical = vertical_.transition(st.vertical, index - AxialHysteresis::kRoots);
  const char* what = st.vertical == M::Inside ? "vertical slack"
                     : st.vertical == M::Above ? "vertical slack taken up (head L above)"
                                                   : "vertical slack taken up (head L below)";
  event = {what, k.w, EventKind::Kink};
}

bool Coupling::commit_in(State& st, int index, int direction, double, const ElementState<double>& s,
                         Event& event) const {
  const Kinematics k = kinematics(s);
  return commit_crossing<kRoots>(
      index, direction, [&](double* g) { roots_at(st, k, g); }, [&](int i, Event& e) { apply(st, i, k, e); }, event);
}

Coupling::State Coupling::stiffest_mode(const ElementState<double>& s) const {
  // Horizontal: the transition line (K_t >= every slope); vertical: beyond the slack.
  State stiffest = mode_as<State>(s);
  const Kinematics k = kinematics(s);
  stiffest.horizontal = AxialHysteresis::State{};
  stiffest.horizontal.mode = AxialHysteresis::Mode::Transition;
  stiffest.horizontal.x0 = law_.side_deflection(stiffest.horizontal, k.u);
  if (vertical_stiffness > 0.0) stiffest.vertical = DeadBand::Mode::Above;
  return stiffest;
}

double Coupling::potential_energy(const ElementState<double>& s) const {
  const State& st = mode_as<State>(s);
  const Kinematics k = kinematics(s);
  return law_.energy(st.horizontal, k.u) + vertical_.energy(st.vertical, k.w);
}

void Coupling::outputs(const ElementState<double>& s, const double*, double* out) const {
  const State& st = mode_as<State>(s);
  const Kinematics k = kinematics(s);
  out[0] = law_.force(st.horizontal, k.u);
  out[1] = k.u;
  out[2] = vertical_.force(st.vertical, k.w);
  out[3] = k.w;
  out[4] = friction > 0.0
               ? -friction * law_.magnitude(st.horizontal, k.u) * std::tanh(k.w_rate / friction_velocity)
               : 0.0;
}

namespace {

ParameterSpec friction_velocity_spec() {
  return {"friction_velocity", Unit::Velocity, default_velocity(0.01), Range::Positive,
          "vertical sliding speed over which the friction builds up (tanh(v / friction_velocity))"};
}

}  // namespace

void register_couplers_elements(ElementRegistry& registry) {
  registry.add(
      {"draft_gear", "13", 2, "P1 on body 1, P2 on body 2: the ends of the gear (yoke and draft pocket)",
       "Friction draft gear along P1-P2: compression d = free_length - L, mirror-symmetric in draft: stuck by "
       "friction until breakaway, loads on initial_stiffness d + hysteresis_load, bottoms at `travel` "
       "(stiffness_after_bottoming beyond), unloads elastically (transition_stiffness) down to "
       "initial_stiffness d - hysteresis_load, released at zero force. Buff overload shears the pin: free "
       "travel for post_shear_travel, then solid. Fracture at |F| = fracture_load. Its points meeting (within "
       "1e-3 free_length) or passing each other while it carries force stops the run, naming it.",
       {{"initial_stiffness", Unit::ForcePerLength, required, Range::Positive, "slope of the gear before bottoming"},
        {"travel", Unit::Length, required, Range::Positive, "compression at which the gear bottoms"},
        {"stiffness_after_bottoming", Unit::ForcePerLength, required, Range::Positive, "slope beyond `travel`"},
        {"hysteresis_load", Unit::Force, required, Range::Positive,
         "friction force: loading lies this far above, unloading this far below the spring line"},
        {"pin_shear_load", Unit::Force, optional("no pin shear"), Range::Positive,
         "buff force at which the shear pin fails"},
        {"post_shear_travel", Unit::Length, optional("0 (needs pin_shear_load)"), Range::NonNegative,
         "free travel after the pin shears, before the gear is solid"},
        {"fracture_load", Unit::Force, optional("no fracture"), Range::Positive,
         "force (buff or draft) at which the gear breaks"},
        {"transition_stiffness", Unit::ForcePerLength, optional("stiffness_after_bottoming"), Range::Positive,
         "slope of the elastic line between loading and unloading; above initial_stiffness, at least "
         "stiffness_after_bottoming"},
        {"free_length", Unit::Length, optional("the initial distance P1-P2"), Range::Positive,
         "length of the gear at rest"}},
       "initial_stiffness: 24000\ntravel: 1.25\nstiffness_after_bottoming: 320000\nhysteresis_load: 10000\n"
       "pin_shear_load: 150000\npost_shear_travel: 1.375\nfracture_load: 250000",
       [](ElementSpec& s) { return std::make_unique<DraftGear>(s); }});
  registry.add(
      {"coupler_end", "14", 2, "P1 on coupler K, P2 on coupler L, each free_length behind its face",
       "Two coupler faces in contact: vertical faces along global x, the two horizontal stiffnesses in series; the faces "
       "push when closer than their contact spacing, and pull only when coupled and past the total horizontal "
       "slack; only while the faces overlap vertically (coupler_height). Friction mu |T| tanh(Dy' / "
       "friction_velocity) between the faces. With restitution e < 1 (uncoupled only) the faces unload and reload "
       "along slope k / e^2 and keep a permanent set. The faces shear off at shear_load (buff).",
       {{"horizontal_stiffness", Unit::ForcePerLength, required, Range::Positive, "face stiffness [end K, end L]",
         Shape::Pair},
        {"free_length", Unit::Length, required, Range::NonNegative,
         "distance from each point to its face [end K, end L]", Shape::Pair},
        {"coupler_height", Unit::Length, required, Range::Positive, "height of each face [end K, end L]", Shape::Pair},
        {"coupled", Unit::Choice, default_flag(false), Range::Any, "true: the knuckles also carry draft",
         Shape::Flag},
        {"total_horizontal_slack", Unit::Length, default_value(0.0), Range::NonNegative,
         "free play of coupled knuckles between buff and draft contact (coupled only)"},
        {"friction", Unit::Dimensionless, default_value(0.0), Range::NonNegative,
         "friction coefficient mu between the faces"},
        friction_velocity_spec(),
        {"restitution", Unit::Dimensionless, default_value(1.0), Range::Fraction,
         "coefficient of restitution of the buff contact (below 1: uncoupled faces only)"},
        {"shear_load", Unit::Force, optional("the faces never shear"), Range::Positive,
         "buff face force at which the faces shear off"}},
       "horizontal_stiffness: [1.0e6, 1.0e6]\nfree_length: [0.5, 0.5]\ncoupler_height: [0.1, 0.1]\n"
       "restitution: 0.8\nshear_load: 1.0e6",
       [](ElementSpec& s) { return std::make_unique<CouplerEnd>(s); }});
  registry.add(
      {"coupling", "11 (kind: 1), 12 (kind: 2)", 2, "P1 on car 1, P2 on car 2",
       "Freight coupler: a hysteretic nonlinear horizontal spring with slack, mirror-symmetric in draft (kind 1: "
       "one loading `curve`, unloading at unloading_factor times it; kind 2: separate loading and unloading "
       "curves), a vertical dead-band spring between the heads, and sliding friction proportional to the "
       "horizontal force.",
       {{"kind", Unit::Choice, default_value(1), Range::Any,
         "1: curve + unloading_factor (report type 11), 2: loading_curve + unloading_curve (type 12)"},
        {"curve", Unit::LengthForceCurve, optional("none; kind 1 needs it"), Range::Any,
         "kind 1: loading curve [[deflection, force], ...] from [0, 0], deflection increasing", Shape::Table},
        {"unloading_factor", Unit::Dimensionless, optional("none; kind 1 needs it"), Range::UnitInterval,
         "kind 1: unloading force over loading force"},
        {"loading_curve", Unit::LengthForceCurve, optional("none; kind 2 needs it"), Range::Any,
         "kind 2: loading curve [[deflection, force], ...] from [0, 0]", Shape::Table},
        {"unloading_curve", Unit::LengthForceCurve, optional("none; kind 2 needs it"), Range::Any,
         "kind 2: unloading curve, nowhere above the loading curve", Shape::Table},
        {"horizontal_slack", Unit::Length, default_value(0.0), Range::NonNegative, "total horizontal free play"},
        {"vertical_slack", Unit::Length, default_value(0.0), Range::NonNegative, "total vertical free play of the heads"},
        {"vertical_stiffness", Unit::ForcePerLength, default_value(0.0), Range::NonNegative,
         "vertical spring outside the slack (0: none)"},
        {"misalignment", Unit::Length, default_value(0.0), Range::Any,
         "initial vertical offset of the heads when the points are level"},
        {"friction", Unit::Dimensionless, default_value(0.0), Range::NonNegative,
         "friction coefficient mu between the heads"},
        friction_velocity_spec(),
        {"transition_stiffness", Unit::ForcePerLength, optional("the steepest slope of the curves"), Range::Positive,
         "slope of the elastic line between loading and unloading"},
        {"free_length", Unit::Length, optional("the initial spacing"), Range::NonNegative,
         "spacing of the points at the centre of the horizontal slack"}},
       "kind: 1\ncurve: [[0, 0], [0.5, 1.0e5], [1.0, 3.0e5]]\nunloading_factor: 0.5\nhorizontal_slack: 0.1\n"
       "vertical_slack: 0.05\nvertical_stiffness: 1.0e5",
       [](ElementSpec& s) { return std::make_unique<Coupling>(s); }});
}

}  // namespace railcrash
