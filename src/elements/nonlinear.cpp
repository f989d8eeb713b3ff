#include "railcrash/elements/nonlinear.hpp"

#include <cmath>
#include <string>

#include "railcrash/model/element_registry.hpp"

namespace railcrash {

// ---- PiecewiseLinearLaw ------------------------------------------------------------------

PiecewiseLinearLaw::PiecewiseLinearLaw(const std::vector<double>& breakpoints, const std::vector<Segment>& segments) {
  RAILCRASH_DEMAND(segments.size() == breakpoints.size() + 1);
  const std::size_t n = breakpoints.size();
  append(segments[0], 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    RAILCRASH_DEMAND(i == 0 || breakpoints[i] >= breakpoints[i - 1]);
    // Segment i + 1 lies between breakpoints i and i + 1: empty when they coincide.
    if (i + 1 < n && breakpoints[i + 1] == breakpoints[i]) continue;
    const Segment& next = segments[i + 1];
    const int last = count_ - 1;
    const double b = breakpoints[i];
    const double below = value(b, last), above = next.intercept + next.slope * b;
    if (next.slope == slope_[index(last)] && std::abs(below - above) <= 1e-12 * (std::abs(below) + std::abs(above))) {
      names_.back() += " / " + next.name;  // the same straight line: no kink here
      continue;
    }
    append(next, b);
  }
  // Antiderivatives G_k(x) = C_k + a_k x + s_k x^2 / 2, with G(0) = 0 and G continuous.
  const auto line_integral = [this](int k, double x) { return intercept_[index(k)] * x + 0.5 * slope_[index(k)] * x * x; };
  const int home = segment_at(0.0, 1);
  for (int k = home; k + 1 < segment_count(); ++k) {
    const double b = upper(k);
    integral_constant_[index(k + 1)] = integral_constant_[index(k)] + line_integral(k, b) - line_integral(k + 1, b);
  }
  for (int k = home; k > 0; --k) {
    const double b = lower(k);
    integral_constant_[index(k - 1)] = integral_constant_[index(k)] + line_integral(k, b) - line_integral(k - 1, b);
  }
}

void PiecewiseLinearLaw::append(const Segment& segment, double lower_breakpoint) {
  RAILCRASH_DEMAND(count_ < kMaxSegments);
  if (count_ > 0) breakpoints_[index(count_ - 1)] = lower_breakpoint;
  intercept_[index(count_)] = segment.intercept;
  slope_[index(count_)] = segment.slope;
  names_.push_back(segment.name);
  ++count_;
}

PiecewiseLinearLaw PiecewiseLinearLaw::two_branch(double value_at_zero, const Branch& negative,
                                                  const std::string& negative_name, const Branch& positive,
                                                  const std::string& positive_name) {
  std::vector<double> breakpoints;
  std::vector<Segment> segments;
  if (negative.breakpoint) {
    const double distance = *negative.breakpoint;
    const double value = value_at_zero - negative.slope_1 * distance;  // f(-distance)
    segments.push_back({value + *negative.slope_2 * distance, *negative.slope_2, negative_name + " segment 2"});
    breakpoints.push_back(-distance);
  }
  segments.push_back({value_at_zero, negative.slope_1, negative_name + " segment 1"});
  breakpoints.push_back(0.0);
  segments.push_back({value_at_zero, positive.slope_1, positive_name + " segment 1"});
  if (positive.breakpoint) {
    const double distance = *positive.breakpoint;
    const double value = value_at_zero + positive.slope_1 * distance;  // f(+distance)
    segments.push_back({value - *positive.slope_2 * distance, *positive.slope_2, positive_name + " segment 2"});
    breakpoints.push_back(distance);
  }
  return PiecewiseLinearLaw(breakpoints, segments);
}

double PiecewiseLinearLaw::integral(double x, int k) const {
  return integral_constant_[index(k)] + intercept_[index(k)] * x + 0.5 * slope_[index(k)] * x * x;
}

int PiecewiseLinearLaw::segment_at(double x, int direction) const {
  const int n = segment_count();
  if (direction > 0) {  // the highest segment whose lower breakpoint is at or below x
    int k = 0;
    while (k + 1 < n && upper(k) <= x) ++k;
    return k;
  }
  int k = n - 1;  // the lowest segment whose upper breakpoint is at or above x
  while (k > 0 && lower(k) >= x) --k;
  return k;
}

// ---- PiecewiseLineElement ----------------------------------------------------------------

template <class Derived>
PiecewiseLineElement<Derived>::PiecewiseLineElement(ElementSpec& spec, int fracture_sides)
    : HybridElement<Derived>(spec.name, spec.type, spec.points, spec.where), fracture_sides_(fracture_sides) {}

template <class Derived>
void PiecewiseLineElement<Derived>::set_law(PiecewiseLinearLaw law) {
  law_ = std::move(law);
  double size = 0.0;
  for (double b : law_.breakpoints()) size = std::max(size, std::abs(b));
  root_band_ = 1e-14 * std::max(1.0, size);
}

template <class Derived>
void PiecewiseLineElement<Derived>::initialize(const ElementState<double>& initial) {
  Derived& self = *static_cast<Derived*>(this);
  self.prepare(initial);
  if (checks_points_meet_) points_meet_.initialize(*this, initial);
  const double x = self.measure(initial);
  SegmentMode& m = initial_mode_;
  m = SegmentMode{};
  // On a breakpoint: the segment x moves into; the lower one when that is unknown (the
  // integrators' start check commits the crossing if the motion goes up).
  m.segment = law_.segment_at(x, self.rate_sign(initial) > 0 ? 1 : -1);
  if (fracture_roots() > 0) {
    const double f = law_.value(x, m.segment);
    if (f >= *fracture_load || (fracture_roots() > 1 && -f >= *fracture_load))
      throw InputError(this->where().prefix() + this->type() + " '" + this->name() + "' starts at a force of " +
                       std::to_string(f) + ", beyond its fracture_load " + std::to_string(*fracture_load) +
                       "; raise fracture_load or start it less deformed");
  }
}

template <class Derived>
void PiecewiseLineElement<Derived>::roots_in(const SegmentMode& m, const ElementState<double>& s, double* g) const {
  for (int k = 0; k < root_count(); ++k) g[k] = 1.0;
  if (m.broken) return;
  const double x = measure_of(s);
  const int k = m.segment;
  if (law_.has_lower(k)) g[0] = x - law_.lower(k) + root_band_;
  if (law_.has_upper(k)) g[1] = law_.upper(k) - x + root_band_;
  if (fracture_roots() > 0) {
    const double f = law_.value(x, k);
    g[2] = *fracture_load - f;
    if (fracture_roots() > 1) g[3] = *fracture_load + f;
  }
  if (checks_points_meet_) g[points_meet_root()] = points_meet_gap(s);
}

template <class Derived>
double PiecewiseLineElement<Derived>::points_meet_gap(const ElementState<double>& s) const {
  const double free_length = static_cast<const Derived*>(this)->points_meet_length();
  return free_length > 0.0 ? points_meet_.gap(*this, s, free_length) : 1.0;
}

template <class Derived>
bool PiecewiseLineElement<Derived>::commit_in(SegmentMode& m, int index, int direction, double t,
                                              const ElementState<double>& s, Element::Event& event) const {
  if (m.broken) return false;
  if (checks_points_meet_ &&
      points_meet_.met(*this, s, static_cast<const Derived*>(this)->points_meet_length(), index, points_meet_root(), direction))
    points_meet_.stop(*this, t, s, static_cast<const Derived*>(this)->points_meet_length(), "", PointsMeet::kSpringAdvice);
  if (checks_points_meet_ && index == points_meet_root()) return false;
  const double x = measure_of(s);
  if (index >= 2) {  // fracture roots: leave when they fall through zero
    if (direction > 0) return false;
    event = {"fracture", law_.value(x, m.segment)};
    m.broken = true;
    return true;
  }
  // Root 0 (x - lower) falls when x moves down, root 1 (upper - x) when x moves up. The new
  // segment comes from x itself, so a step over several breakpoints (Euler) lands right,
  // and a second root of the same crossing finds nothing left to do.
  const int x_direction = index == 0 ? direction : -direction;
  const int to = law_.segment_at(x, x_direction);
  if (to == m.segment) return false;
  const int from = m.segment;
  m.segment = to;
  event = static_cast<const Derived*>(this)->segment_event(from, to, x);
  // The piecewise-linear laws are continuous across their breakpoints; a special spring that
  // closes onto a preload is not, and the integrator finds that jump at the event and restarts.
  event.kind = Element::EventKind::Kink;
  return true;
}

template <class Derived>
double PiecewiseLineElement<Derived>::law_integral(const ElementState<double>& s) const {
  const SegmentMode& m = mode_as<SegmentMode>(s);
  return m.broken ? 0.0 : law_.integral(measure_of(s), m.segment);
}

template <class Derived>
SegmentMode PiecewiseLineElement<Derived>::stiffest_mode(const ElementState<double>& /*s*/) const {
  SegmentMode steepest;  // unbroken, on the segment of the largest |slope|
  for (int k = 1; k < law_.segment_count(); ++k)
    if (std::abs(law_.segment(k).slope) > std::abs(law_.segment(steepest.segment).slope)) steepest.segment = k;
  return steepest;
}

template <class Derived>
void PiecewiseLineElement<Derived>::outputs(const ElementState<double>& s, const double*, double* out) const {
  const double x = measure_of(s);
  out[0] = law_value(mode_as<SegmentMode>(s), x);
  out[1] = x;
}

namespace {

int sign_of(double value) { return (value > 0.0) - (value < 0.0); }

/// Rate of length L' = u . (r2' - r1').
double length_rate(const ElementState<double>& s, const Element& e) {
  const LineGeometry<double> g = line_geometry(e, s);
  return dot(g.d, g.d_rate) / g.length;
}

/// slope_1 (required), slope_2 and breakpoint (together or neither), all >= 0.
PiecewiseLinearLaw::Branch read_branch(ParameterReader& p, const std::string& slope_1, const std::string& slope_2,
                                       const std::string& breakpoint) {
  PiecewiseLinearLaw::Branch branch;
  branch.slope_1 = p.value(slope_1);
  branch.slope_2 = p.number(slope_2);
  branch.breakpoint = p.number(breakpoint);
  if (branch.slope_2 && !branch.breakpoint)
    p.fail(slope_2, "'" + slope_2 + "' needs '" + breakpoint + "' (where it takes over from '" + slope_1 +
                        "'): give both or neither");
  if (branch.breakpoint && !branch.slope_2)
    p.fail(breakpoint, "'" + breakpoint + "' needs '" + slope_2 + "' (the slope beyond it): give both or neither");
  return branch;
}

}  // namespace

// ---- nonlinear_spring --------------------------------------------------------------------

NonlinearSpring::NonlinearSpring(ElementSpec& spec)
    : PiecewiseLineElement<NonlinearSpring>(spec, 2),
      compression(read_branch(*spec.parameters, "compression_stiffness_1", "compression_stiffness_2",
                              "compression_breakpoint")),
      extension(read_branch(*spec.parameters, "extension_stiffness_1", "extension_stiffness_2", "extension_breakpoint")),
      preload(spec.parameters->value("preload")),
      free_length(spec.parameters->number("free_length")) {
  fracture_load = spec.parameters->number("fracture_load");
  if (fracture_load && std::abs(preload) >= *fracture_load)
    spec.parameters->fail("preload", "'preload' must be smaller in size than 'fracture_load' (the spring would break at once)");
  set_law(PiecewiseLinearLaw::two_branch(-preload, compression, "compression", extension, "extension"));
  // A tension-only tie (no preload, no compression stiffness) is slack when its points meet:
  // its force is zero whatever the direction, so they may pass.
  const bool pushes_in_compression =
      preload != 0.0 || compression.slope_1 != 0.0 || (compression.slope_2 && *compression.slope_2 != 0.0);
  set_points_meet(pushes_in_compression);
}

int NonlinearSpring::rate_sign(const ElementState<double>& s) const { return sign_of(length_rate(s, *this)); }

void NonlinearSpring::prepare(const ElementState<double>& initial) {
  require_direction(*this, initial);
  if (!free_length) free_length = line_geometry(*this, initial).length;
}

Element::Event NonlinearSpring::segment_event(int, int to, double x) const { return {law().segment_name(to), x}; }

// ---- nonlinear_dashpot -------------------------------------------------------------------

NonlinearDashpot::NonlinearDashpot(ElementSpec& spec)
    : PiecewiseLineElement<NonlinearDashpot>(spec, 0),
      compression(read_branch(*spec.parameters, "damping_compression_1", "damping_compression_2",
                              "compression_switch_velocity")),
      extension(read_branch(*spec.parameters, "damping_extension_1", "damping_extension_2", "extension_switch_velocity")) {
  set_law(PiecewiseLinearLaw::two_branch(0.0, compression, "compression", extension, "extension"));
}

double NonlinearDashpot::measure(const ElementState<double>& s) const { return length_rate(s, *this); }

void NonlinearDashpot::prepare(const ElementState<double>& initial) { require_direction(*this, initial); }

Element::Event NonlinearDashpot::segment_event(int, int to, double x) const { return {law().segment_name(to), x}; }

// ---- special_spring ----------------------------------------------------------------------

SpecialSpring::SpecialSpring(ElementSpec& spec) : PiecewiseLineElement<SpecialSpring>(spec, 1) {
  ParameterReader& p = *spec.parameters;
  const double kind_value = p.value("kind");
  if (kind_value != 1.0 && kind_value != 2.0)
    p.fail("kind", "'kind' must be 1 (acts in compression, pushes the points apart) or 2 (acts in tension, pulls them together)");
  kind = static_cast<int>(kind_value);
  closed = read_branch(p, "stiffness_1", "stiffness_2", "breakpoint");
  preload = p.value("preload");
  if (const auto a = p.vector("axis", 2)) {
    const double size = std::hypot((*a)[0], (*a)[1]);
    if (!(size > 0.0)) p.fail("axis", "'axis' must be a nonzero direction [ax, ay]");
    axis = Vec2<double>{(*a)[0] / size, (*a)[1] / size};
  }
  // Along an axis the separation s has a sign, so any free length will do.
  free_length = p.number("free_length");
  if (!axis && free_length && !(*free_length > 0.0))
    p.fail("free_length", "'free_length' must be positive without an 'axis' (it is a distance between the points)");
  fracture_load = p.number("fracture_load");
  if (fracture_load && preload >= *fracture_load)
    p.fail("preload", "'preload' must be below 'fracture_load' (the spring would break as soon as it closes)");

  std::vector<double> breakpoints{0.0};
  std::vector<PiecewiseLinearLaw::Segment> segments{{0.0, 0.0, "open"}, {preload, closed.slope_1, "segment 1"}};
  if (closed.breakpoint) {
    const double b = *closed.breakpoint;
    const double value = preload + closed.slope_1 * b;  // P(breakpoint)
    segments.push_back({value - *closed.slope_2 * b, *closed.slope_2, "segment 2"});
    breakpoints.push_back(b);
  }
  set_law(PiecewiseLinearLaw(breakpoints, segments));
  set_points_meet(kind == 1 && !axis);  // along an axis the separation has a sign; in tension it pushes nothing
}

double SpecialSpring::separation(const ElementState<double>& s) const {
  return axis ? axis_geometry(s).along : line_geometry(*this, s).length;
}

int SpecialSpring::rate_sign(const ElementState<double>& s) const {
  if (!axis) return sign_of(-direction() * length_rate(s, *this));
  // s' = (r2' - r1') . a + (r2 - r1) . a',  a' = omega_1 perp(a)
  const AxisGeometry<double> g = axis_geometry(s);
  const PointRef& p1 = point(0);
  const PointRef& p2 = point(1);
  const std::size_t k1 = slot_of(0), k2 = slot_of(1);
  const Vec2<double> r1 = point_position(s.q[k1], s.rotation[k1], p1.sx, p1.sy);
  const Vec2<double> relative_rate =
      point_velocity(s.v[k2], s.rotation[k2], p2.sx, p2.sy) - point_velocity(s.v[k1], s.rotation[k1], p1.sx, p1.sy);
  const Vec2<double> a_rate{-s.v[k1].theta * g.a.y, s.v[k1].theta * g.a.x};
  return sign_of(-direction() * (dot(relative_rate, g.a) + dot(g.r2 - r1, a_rate)));
}

void SpecialSpring::prepare(const ElementState<double>& initial) {
  if (!axis) require_direction(*this, initial);
  if (!free_length) free_length = separation(initial);
}

Element::Event SpecialSpring::segment_event(int from, int to, double x) const {
  if (to == 0) return {"opening", x};
  if (from == 0) return {"closing (" + law().segment_name(to) + ")", x};
  return {law().segment_name(to), x};
}

template class PiecewiseLineElement<NonlinearSpring>;
template class PiecewiseLineElement<NonlinearDashpot>;
template class PiecewiseLineElement<SpecialSpring>;

namespace {

/// slope_1 (required), slope_2 and breakpoint of one branch of a piecewise-linear law.
std::vector<ParameterSpec> branch_specs(const std::string& slope_1, const std::string& slope_2,
                                        const std::string& breakpoint, const std::string& branch, Unit slope_unit,
                                        Unit breakpoint_unit) {
  return {{slope_1, slope_unit, required, Range::NonNegative, "first slope of the " + branch},
          {slope_2, slope_unit, optional("the first slope throughout"), Range::NonNegative,
           "slope of the " + branch + " beyond " + breakpoint + " (give both or neither)"},
          {breakpoint, breakpoint_unit, optional("none"), Range::NonNegative,
           "where the " + branch + " changes from " + slope_1 + " to " + slope_2}};
}

std::vector<ParameterSpec> joined(std::vector<ParameterSpec> first, const std::vector<ParameterSpec>& second) {
  first.insert(first.end(), second.begin(), second.end());
  return first;
}

ParameterSpec fracture_spec() {
  return {"fracture_load", Unit::Force, optional("no fracture"), Range::Positive,
          "force at which the element breaks (no force afterwards)"};
}

}  // namespace

void register_nonlinear_elements(ElementRegistry& registry) {
  const std::string ends = "P1 on body 1, P2 on body 2: the ends";
  registry.add(
      {"nonlinear_spring", "19", 2, ends,
       "Piecewise-linear spring along P1-P2: two slopes on each side of e = L - free_length: tension T = -preload + "
       "compression_stiffness_1 e (e < 0) or extension_stiffness_1 e (e > 0), continuing with the second slope beyond "
       "the breakpoint; continuous in e, elastic; breaks when |T| reaches fracture_load. Its points meeting (within "
       "1e-3 free_length) or passing each other stops the run, naming it, unless it pushes nothing in compression "
       "(no preload, no compression stiffness: a tension-only tie, slack there).",
       joined(joined(branch_specs("compression_stiffness_1", "compression_stiffness_2", "compression_breakpoint",
                                  "compression branch", Unit::ForcePerLength, Unit::Length),
                     branch_specs("extension_stiffness_1", "extension_stiffness_2", "extension_breakpoint",
                                  "extension branch", Unit::ForcePerLength, Unit::Length)),
              {{"preload", Unit::Force, default_value(0.0), Range::Any,
                "compressive force at the free length (positive pushes the points apart)"},
               fracture_spec(),
               {"free_length", Unit::Length, optional("the initial distance P1-P2"), Range::Positive,
                "length at which the tension is -preload"}}),
       "compression_stiffness_1: 1000\ncompression_stiffness_2: 5000\ncompression_breakpoint: 0.1\n"
       "extension_stiffness_1: 500\nfracture_load: 1.0e4",
       [](ElementSpec& s) { return std::make_unique<NonlinearSpring>(s); }});
  registry.add(
      {"nonlinear_dashpot", "20", 2, ends,
       "Piecewise-linear dashpot along P1-P2: tension continuous and piecewise linear in the rate L': damping_compression_1 L' "
       "(L' < 0) or damping_extension_1 L' (L' > 0), continuing with the second coefficient beyond the switch "
       "velocity.",
       joined(branch_specs("damping_compression_1", "damping_compression_2", "compression_switch_velocity",
                           "compression branch", Unit::ForceTimePerLength, Unit::Velocity),
              branch_specs("damping_extension_1", "damping_extension_2", "extension_switch_velocity", "extension branch",
                           Unit::ForceTimePerLength, Unit::Velocity)),
       "damping_compression_1: 100\ndamping_extension_1: 50\ndamping_extension_2: 10\nextension_switch_velocity: 1",
       [](ElementSpec& s) { return std::make_unique<NonlinearDashpot>(s); }});
  registry.add(
      {"special_spring", "21", 2, ends + " (with an axis: P2 against a stop plane of body 1)",
       "One-sided contact spring: kind 1 acts in compression (d = free_length - L, pushes the points apart), kind 2 "
       "in tension (d = L - free_length, pulls them together). No force while d < 0; P = preload + stiffness_1 d, "
       "then stiffness_2 beyond the breakpoint. With an axis the length is measured along it and the force acts "
       "along it. Breaks when P reaches fracture_load. Kind 1 without an axis: its points meeting (within 1e-3 "
       "free_length) or passing each other stops the run, naming it.",
       joined({{"kind", Unit::Choice, default_value(1), Range::Any, "1: acts in compression, 2: acts in tension"}},
              joined(branch_specs("stiffness_1", "stiffness_2", "breakpoint", "closed law", Unit::ForcePerLength,
                                  Unit::Length),
                     {{"preload", Unit::Force, default_value(0.0), Range::NonNegative,
                       "force as soon as the spring closes (an installed, caged spring)"},
                      fracture_spec(),
                      {"free_length", Unit::Length, optional("the initial distance (or separation along the axis)"),
                       Range::Any, "length (or separation along the axis) at which it closes; > 0 without an axis"},
                      {"axis", Unit::Direction, optional("along P1-P2"), Range::Any,
                       "direction in body 1's frame along which the separation is measured", Shape::Pair}})),
       "kind: 1\nstiffness_1: 5000\nstiffness_2: 3.0e6\nbreakpoint: 1.25\npreload: 1250\nfracture_load: 4.0e5\n"
       "free_length: 1.25\naxis: [1, 0]",
       [](ElementSpec& s) { return std::make_unique<SpecialSpring>(s); }});
}

}  // namespace railcrash
