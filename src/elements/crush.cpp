#include "railcrash/elements/crush.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdio>
#include <sstream>

#include "railcrash/core/error.hpp"
#include <string>

namespace railcrash {

CrushSpring::CrushSpring(ElementSpec& spec)
    : HybridElement(spec.name, spec.type, spec.points, spec.where),
      unloading_stiffness(spec.parameters->value("unloading_stiffness")),
      tension_stiffness(spec.parameters->number("tension_stiffness")),
      free_length(spec.parameters->number("free_length")) {
  const auto table = spec.parameters->table("curve", 2);  // required: the reader fails when it is absent
  if (table->size() < 2) spec.parameters->fail("curve", "'curve' needs at least two points [[crush, force], ...]");
  for (std::size_t k = 0; k < table->size(); ++k) {
    const double crush = (*table)[k][0], force = (*table)[k][1];
    if (k > 0 && !(crush > curve_crush.back()))
      spec.parameters->fail("curve", "'curve' point " + std::to_string(k + 1) + ": crush values must increase strictly");
    curve_crush.push_back(crush);
    curve_force.push_back(force);
  }
  // Unloading from a crush d_max on a segment of slope s follows the line of slope
  // unloading_stiffness k_u through (d_max, F(d_max)); just below d_max that line lies above the
  // curve exactly when k_u < s (F(d_max) - k_u e > F(d_max) - s e for a small e > 0), and when
  // k_u >= every slope it never rises above the curve (F(d_max) - F(d) <= k_u (d_max - d)). Every
  // segment can be reached (the last one continues without end), so the rule is k_u >= the
  // steepest slope; otherwise unloading would carry more force than crushing did and store more
  // energy than the work done on the element (a negative dissipation). Within 1e-9 of the
  // slope counts as equal (a curve and stiffness converted between units round differently; the
  // scenario generator's check, src/scenarios/en15227.cpp, allows the same).
  int steepest = 0;
  for (int k = 1; k + 1 < static_cast<int>(curve_crush.size()); ++k)
    if (segment_slope(k) > segment_slope(steepest)) steepest = k;
  const double steepest_slope = segment_slope(steepest);
  unloading_above_curve = *spec.parameters->flag("unloading_above_curve");
  if (unloading_stiffness < steepest_slope * (1.0 - 1e-9) && !unloading_above_curve) {
    std::ostringstream what;
    what.precision(6);
    what << "'unloading_stiffness' " << unloading_stiffness << " is below the slope " << steepest_slope
         << " of its curve between points " << steepest + 1 << " and " << steepest + 2 << " (crush "
         << curve_crush[static_cast<std::size_t>(steepest)] << " to " << curve_crush[static_cast<std::size_t>(steepest + 1)]
         << "): unloading from that segment would rise above the loading curve. The unloading stiffness must be at least "
            "the curve's steepest slope: give unloading_stiffness >= "
         << steepest_slope << ", or make the curve less steep there";
    spec.parameters->fail("unloading_stiffness", what.str());
  }
}

double CrushSpring::segment_slope(int segment) const {
  const auto k = static_cast<std::size_t>(segment);
  return (curve_force[k + 1] - curve_force[k]) / (curve_crush[k + 1] - curve_crush[k]);
}

double CrushSpring::curve_at(double crush) const {
  int k = 0;
  const int last = static_cast<int>(curve_crush.size()) - 2;
  while (k < last && crush > curve_crush[static_cast<std::size_t>(k + 1)]) ++k;
  return curve_force[static_cast<std::size_t>(k)] + segment_slope(k) * (crush - curve_crush[static_cast<std::size_t>(k)]);
}

double CrushSpring::crush_of(const ElementState<double>& s) const { return *free_length - line_geometry(*this, s).length; }

double CrushSpring::crush_rate_of(const ElementState<double>& s) const {
  const LineGeometry<double> g = line_geometry(*this, s);
  return -dot(g.d, g.d_rate) / g.length;
}

void CrushSpring::enter_mode_at(State& st, double crush, double rate) const {
  if (crush < st.permanent_crush || (crush == st.permanent_crush && rate <= 0.0)) {
    st.mode = Mode::Open;
    return;
  }
  if (st.crushed && (crush < st.max_crush || (crush == st.max_crush && rate <= 0.0))) {
    st.mode = Mode::Elastic;
    return;
  }
  st.mode = Mode::Loading;
  st.crushed = true;
  st.segment = 0;
  const int last = static_cast<int>(curve_crush.size()) - 2;
  while (st.segment < last && crush >= curve_crush[static_cast<std::size_t>(st.segment + 1)]) ++st.segment;
}

void CrushSpring::initialize(const ElementState<double>& initial) {
  require_direction(*this, initial);
  const LineGeometry<double> g = line_geometry(*this, initial);
  if (!free_length) free_length = g.length;
  // A start crushed by no more than the round-off of its points' coordinates is a start at the
  // free length, which then becomes the points' distance (as when it is not given): a model
  // placed 1 km from the origin computed 0.8 m - 4.6e-14 m for points declared 0.8 m apart and
  // was refused as "starts crushed" (tests/robustness/models/stiff_anticlimber_unit.yaml
  // shifted by 1,000 m in x).
  double coordinates = g.length;  // [length] the size of the numbers the distance came from
  for (int slot = 0; slot < 2; ++slot)
    coordinates += std::abs(initial.q[static_cast<std::size_t>(slot)].x) + std::abs(initial.q[static_cast<std::size_t>(slot)].y);
  for (const PointRef& p : points()) coordinates += std::abs(p.sx) + std::abs(p.sy);
  constexpr double kRoundOffUlps = 16.0;  // a sum of positions and offsets, a difference and a square root
  const double crushed = *free_length - g.length;
  if (crushed > 0.0 && crushed <= kRoundOffUlps * std::numeric_limits<double>::epsilon() * coordinates) free_length = g.length;
  points_meet_.initialize(*this, initial);
  initial_state_ = State{};
  const double crush = crush_of(initial);
  enter_mode_at(initial_state_, crush, crush_rate_of(initial));
  if (initial_state_.mode == Mode::Loading && crush > 0.0) {
    char crushed_by[32];
    std::snprintf(crushed_by, sizeof crushed_by, "%.6g", crush);  // (round-off shows as such, not as 0.000000)
    throw InputError(where().prefix() + "crush_spring '" + name() + "' starts crushed by " + crushed_by +
                     "; start it at or beyond its free_length (it has no crush history)");
  }
}

void CrushSpring::stiffest_force_jacobian(double, const ElementState<double>& s, ForceBlock& df_dq,
                                          ForceBlock& df_dv) const {
  // Stiffest of: the unloading stiffness, the curve's slopes, the tension stiffness.
  double stiffest = unloading_stiffness;
  for (int k = 0; k + 1 < static_cast<int>(curve_crush.size()); ++k) stiffest = std::max(stiffest, segment_slope(k));
  if (tension_stiffness) stiffest = std::max(stiffest, *tension_stiffness);
  State elastic = mode_as<State>(s);
  elastic.mode = Mode::Elastic;
  elastic.permanent_crush = crush_of(s);
  using D = Dual<double, 12>;
  std::array<Pose<D>, 2> fd{};
  line_force_law(ad::seeded_state<D>(s), elastic, stiffest, fd);
  std::array<Pose<double>, 2> f{};
  ad::extract_forces(fd, f, df_dq, df_dv);
}

void CrushSpring::roots_in(const State& st, const ElementState<double>& s, double* g) const {
  const double crush = crush_of(s);
  g[0] = g[1] = g[2] = 1.0;
  g[kPointsMeetRoot] = points_meet_gap(s);
  switch (st.mode) {
    case Mode::Loading: {
      const auto k = static_cast<std::size_t>(st.segment);
      g[0] = crush_rate_of(s);
      if (st.segment > 0) g[1] = crush - curve_crush[k];
      if (st.segment + 2 < static_cast<int>(curve_crush.size())) g[2] = curve_crush[k + 1] - crush;
      break;
    }
    // The elastic line's and the open gap's exits: past the point AND moving that way (crushing
    // again to reload or touch, opening to separate; hybrid.hpp). Without the rate a zone resting
    // on its unloading point chattered there, "unloading" and "reloading on the curve" at one
    // instant: 264,610 events in 10 s of scenario2_emu3 at rtol 1e-7, IDA's step down to 4e-9 s.
    case Mode::Elastic: {
      const double rate = crush_rate_of(s);
      g[0] = position_root_moving_on(st.max_crush - crush, rate);
      g[1] = position_root_moving_on(crush - st.permanent_crush, -rate);
      break;
    }
    case Mode::Open:
      g[0] = position_root_moving_on(st.permanent_crush - crush, crush_rate_of(s));
      break;
  }
}

bool CrushSpring::commit_in(State& st, int index, int direction, double t, const ElementState<double>& s,
                            Event& event) const {
  const double crush = crush_of(s);
  // Checked whatever root fired: a step known at its end alone (Euler's) commits one root per
  // element, and the step that carries P2 past P1 may also reverse the crush rate (root 0, first).
  if (points_meet_.met(*this, s, *free_length, index, kPointsMeetRoot, direction)) {
    // No mode goes on from here: the run stops with what it has (Integrator::run keeps the
    // samples up to now and takes this as the run's message; not a step failure, so auto does
    // not hand the run to Euler either).
    points_meet_.stop(*this, t, s, *free_length, "",
                      "The structure needs a stroke it does not have: give a free_length above the crush its curve "
                      "must reach, a stiffer end of the curve, or less energy to absorb",
                      "is crushed through its whole length");
  }
  switch (st.mode) {
    case Mode::Loading:
      if (direction > 0) return false;
      if (index == 0) {  // crush rate reversed: unload elastically from here
        st.max_crush = crush;
        st.permanent_crush = crush - curve_at(crush) / unloading_stiffness;
        st.mode = Mode::Elastic;
        event = {"unloading", crush, EventKind::Kink};
      } else if (index == 1) {
        --st.segment;
        event = {"curve segment " + std::to_string(st.segment + 1), crush, EventKind::Kink};
      } else {
        ++st.segment;
        event = {"curve segment " + std::to_string(st.segment + 1), crush, EventKind::Kink};
      }
      return true;
    case Mode::Elastic:
      if (direction > 0) return false;
      // Moving back from the point, whatever the position: not crossed (roots_in).
      if (index == 0 ? crush_rate_of(s) < 0.0 : crush_rate_of(s) > 0.0) return false;
      if (index == 0) {
        // Back on the curve at d_max. A restart's look-ahead may commit this a hair before
        // d_max (crush < d_max by round-off): the element reloads all the same, never a
        // "reloading" that leaves it elastic (which would fire again at once).
        enter_mode_at(st, std::max(crush, st.max_crush), 1.0);
        event = {"reloading on the curve", crush, EventKind::Kink};
      } else {
        st.mode = Mode::Open;
        event = {"separation", crush, EventKind::Kink};
      }
      return true;
    case Mode::Open:
      if (direction > 0 || index != 0 || crush_rate_of(s) < 0.0) return false;
      enter_mode_at(st, std::max(crush, st.permanent_crush), 1.0);  // contact (as above: never left open)
      event = {st.mode == Mode::Loading ? "contact, crushing" : "contact", crush, EventKind::Kink};
      return true;
  }
  return false;
}

double CrushSpring::potential_energy(const ElementState<double>& s) const {
  const State& st = mode_as<State>(s);
  const double force = crush_force(st, crush_of(s));
  if (st.mode != Mode::Open) return force * force / (2.0 * unloading_stiffness);
  // Open: only a tension spring (if any) stores energy, k (d - d_p)^2 / 2 = P^2 / (2 k).
  return tension_stiffness ? force * force / (2.0 * *tension_stiffness) : 0.0;
}

void CrushSpring::outputs(const ElementState<double>& s, const double*, double* out) const {
  const double crush = crush_of(s);
  const State& st = mode_as<State>(s);
  out[0] = crush_force(st, crush);
  out[1] = crush;
  out[2] = st.permanent_crush;
}

void register_crush_elements(ElementRegistry& registry) {
  registry.add({"crush_spring", "", 2, "P1 on body 1, P2 on body 2: the ends of the structure",
                "Crushable structure along P1-P2: crush d = free_length - L (positive when shortened), "
                "force P >= 0 pushing the points apart. While crushing P follows the loading `curve` (its last "
                "slope continues beyond it); it unloads and reloads elastically with unloading_stiffness, "
                "remembering the permanent crush; in tension no force (or tension_stiffness when given).",
                {{"curve", Unit::LengthForceCurve, required, Range::NonNegative,
                  "loading curve [[crush, force], ...], crush strictly increasing, at least two points", Shape::Table},
                 {"unloading_stiffness", Unit::ForcePerLength, required, Range::Positive,
                  "slope of elastic unloading and reloading, at least the curve's steepest slope"},
                 {"unloading_above_curve", Unit::Choice, default_flag(false), Range::Any,
                  "true: accept an unloading_stiffness below the curve's steepest slope (unloading from those "
                  "segments rises above the curve and stores more than the work done on it: a negative "
                  "dissipation); for a model that says so, never by default",
                  Shape::Flag},
                 {"tension_stiffness", Unit::ForcePerLength, optional("no force in tension"), Range::Positive,
                  "slope in tension beyond the permanent crush"},
                 {"free_length", Unit::Length, optional("the initial distance P1-P2"), Range::Positive,
                  "length at zero crush"}},
                "curve: [[0, 0], [0.1, 2.0e5], [0.5, 2.5e5]]\nunloading_stiffness: 5.0e6",
                [](ElementSpec& s) { return std::make_unique<CrushSpring>(s); }});
}

}  // namespace railcrash
