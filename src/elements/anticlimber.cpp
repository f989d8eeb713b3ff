#include "railcrash/elements/anticlimber.hpp"

#include <cmath>
#include <string>

namespace railcrash {

// ---- one direction's elastic-plastic law -----------------------------------------------------

ElasticPlasticLaw::State ElasticPlasticLaw::fresh() const {
  State st;
  st.mode = Mode::Elastic;
  st.offset = 0.0;
  st.lower = one_sided ? 0.0 : -yield_deflection;
  st.upper = yield_deflection;
  st.yielded = false;
  return st;
}

void ElasticPlasticLaw::roots(const State& st, double d, double rate, double* g) const {
  g[0] = g[1] = g[2] = 1.0;
  switch (st.mode) {
    case Mode::Elastic:  // yield or reload at either end of the elastic range, moving on to it
      g[0] = position_root_moving_on(st.upper - d, rate);
      g[1] = position_root_moving_on(d - st.lower, -rate);
      break;
    case Mode::PlasticUp:
      g[0] = rate;
      break;
    case Mode::PlasticDown:
      g[1] = -rate;
      break;
    case Mode::Failed:
      return;
  }
  if (rupture_deflection) g[2] = *rupture_deflection - std::abs(d);
}

bool ElasticPlasticLaw::active(const State& st, int index) const {
  if (st.mode == Mode::Failed) return false;
  if (index == 2) return rupture_deflection.has_value();
  if (st.mode == Mode::Elastic) return index == 0 || index == 1;
  return (st.mode == Mode::PlasticUp) ? index == 0 : index == 1;
}

ElasticPlasticLaw::Outcome ElasticPlasticLaw::leave(State& st, int index, double d) const {
  if (index == 2) {
    st.mode = Mode::Failed;
    return Outcome::Rupture;
  }
  if (st.mode == Mode::Elastic) {
    if (index == 1 && one_sided) return Outcome::Release;  // force down to zero: the faces open
    st.mode = index == 0 ? Mode::PlasticUp : Mode::PlasticDown;
    const Outcome outcome = st.yielded ? Outcome::Reloading : Outcome::Yield;
    st.yielded = true;
    return outcome;
  }
  // Plastic flow stops (the deformation rate reversed): elastic from here, with the offset
  // at which the elastic line through the current point reaches zero force.
  const double f = force(st, d);
  st.offset = d - f / elastic_stiffness;
  if (st.mode == Mode::PlasticUp) {
    st.upper = d;
    st.lower = one_sided ? st.offset : d - 2.0 * yield_deflection;
  } else {
    st.lower = d;
    st.upper = d + 2.0 * yield_deflection;
  }
  st.mode = Mode::Elastic;
  return Outcome::Unloading;
}

double ElasticPlasticLaw::elastic_energy(const State& st, double d) const {
  const double f = force(st, d);
  return f * f / (2.0 * elastic_stiffness);
}

// ---- parameters -------------------------------------------------------------------------------

namespace {

const char* const kDirections[3] = {"horizontal", "vertical", "torsional"};

/// One direction's law; `default_rupture` applies when its rupture deflection is not given.
ElasticPlasticLaw make_law(ParameterReader& p, const std::string& direction, std::optional<double> default_rupture,
                           bool one_sided) {
  const std::string elastic = direction + "_elastic_stiffness", plastic = direction + "_plastic_stiffness";
  const std::string yield = direction + "_yield_deflection", rupture = direction + "_rupture_deflection";
  ElasticPlasticLaw law;
  law.elastic_stiffness = p.value(elastic);
  law.plastic_stiffness = p.value(plastic);
  if (!(law.plastic_stiffness < law.elastic_stiffness))
    p.fail(plastic, "'" + plastic + "' must be below '" + elastic + "' (the law must soften at yield)");
  law.yield_deflection = p.value(yield);
  const std::optional<double> given_rupture = p.number(rupture);
  if (given_rupture && !(*given_rupture > law.yield_deflection))
    p.fail(rupture, "'" + rupture + "' must exceed '" + yield + "' (rupture happens in plastic flow); leave it out for no rupture");
  law.rupture_deflection = given_rupture ? given_rupture : default_rupture;
  law.one_sided = one_sided;
  return law;
}

}  // namespace

Anticlimber::Anticlimber(ElementSpec& spec) : HybridElement(spec.name, spec.type, spec.points, spec.where) {
  ParameterReader& p = *spec.parameters;
  length = p.number("length");
  facing = p.number("facing");
  const std::optional<std::string> interlock = p.word("interlock_while_unloading");
  if (*interlock != "hold" && *interlock != "release")
    p.fail("interlock_while_unloading",
           "'interlock_while_unloading' must be hold (the faces keep their vertical and torsional interlock while the "
           "horizontal law unloads) or release (the interlock lets go at the horizontal unloading and re-seats at "
           "reloading), not '" + *interlock + "'");
  release_while_unloading = *interlock == "release";

  horizontal = make_law(p, kDirections[0], length, true);  // default: crushed through over its whole length
  vertical = make_law(p, kDirections[1], std::nullopt, false);
  torsional = make_law(p, kDirections[2], std::nullopt, false);
  if (length && *horizontal.rupture_deflection > *length)
    p.fail("horizontal_rupture_deflection",
           "'horizontal_rupture_deflection' must not exceed 'length' (the structure cannot crush further than its length)");
  face_height = p.value("face_height");
  initial_misalignment = p.value("initial_misalignment");
  const std::optional<std::string> geometry = p.word("misalignment_geometry");
  if (*geometry != "face" && *geometry != "offset")
    p.fail("misalignment_geometry",
           "'misalignment_geometry' must be face (face 2's centre is initial_misalignment above point 2: the forces act "
           "there) or offset (the misalignment is only added to the vertical offset), not '" + *geometry + "'");
  misalignment_at_face = *geometry == "face";
  if (facing && *facing != 1.0 && *facing != -1.0)
    p.fail("facing", "'facing' must be 1 (body 1's face looks along its +x axis) or -1 (along -x)");
}

// ---- geometry and modes -----------------------------------------------------------------------

Anticlimber::Deformations Anticlimber::deformations(const State& st, const ElementState<double>& s) const {
  const Kinematics<double> k = kinematics(s);
  const PointRef& p1 = point(0);
  const PointRef& p2 = point(1);
  const Pose<double>& q1 = s.q[slot1()];
  const Pose<double>& q2 = s.q[slot2()];
  const Pose<double>& v1 = s.v[slot1()];
  const Pose<double>& v2 = s.v[slot2()];
  const Rotation<double>& rotation1 = s.rotation[slot1()];
  const Rotation<double>& rotation2 = s.rotation[slot2()];
  const Vec2<double> d = point_position(q2, rotation2, p2.sx, face2_sy()) - point_position(q1, rotation1, p1.sx, p1.sy);
  const Vec2<double> d_rate = point_velocity(v2, rotation2, p2.sx, face2_sy()) - point_velocity(v1, rotation1, p1.sx, p1.sy);
  // e1' = omega1 n1, n1' = -omega1 e1.
  const double along_rate = dot(d_rate, k.e1) + v1.theta * dot(d, k.n1);
  const double across_rate = dot(d_rate, k.n1) - v1.theta * dot(d, k.e1);
  Deformations out;
  out.offset = k.vertical;
  out.rotation = k.rotation;
  out.d[0] = k.horizontal;
  out.d[1] = k.vertical - st.vertical_reference;
  out.d[2] = k.rotation - st.torsional_reference;
  out.rate[0] = -(*facing) * along_rate;
  out.rate[1] = across_rate;
  out.rate[2] = v2.theta - v1.theta;
  return out;
}

void Anticlimber::roots_of(const State& st, const Deformations& k, double* g) const {
  for (int i = 0; i < kRootCount; ++i) g[i] = 1.0;
  switch (st.contact) {
    case Contact::Open:
      g[kContactRoot] = st.horizontal.offset - k.d[0];
      break;
    case Contact::Engaged:
      horizontal.roots(st.horizontal, k.d[0], k.rate[0], g + kHorizontalRoots);
      if (!st.interlock_released) {
        vertical.roots(st.vertical, k.d[1], k.rate[1], g + kVerticalRoots);
        torsional.roots(st.torsional, k.d[2], k.rate[2], g + kTorsionalRoots);
      }
      g[kOverrideRoot] = face_height - std::abs(k.offset);
      break;
    case Contact::Overridden:
    case Contact::Crushed:
      break;
  }
}

bool Anticlimber::active(const State& st, int index) const {
  switch (st.contact) {
    case Contact::Open:
      return index == kContactRoot;
    case Contact::Engaged:
      if (index == kOverrideRoot) return true;
      if (index == kContactRoot) return false;
      if (index < kVerticalRoots) return horizontal.active(st.horizontal, index - kHorizontalRoots);
      if (st.interlock_released) return false;
      if (index < kTorsionalRoots) return vertical.active(st.vertical, index - kVerticalRoots);
      return torsional.active(st.torsional, index - kTorsionalRoots);
    case Contact::Overridden:
    case Contact::Crushed:
      break;
  }
  return false;
}

void Anticlimber::seat_interlock(State& st, const Deformations& k) const {
  st.interlock_released = false;
  st.vertical_reference = k.offset;
  st.torsional_reference = k.rotation;
  if (st.vertical.mode != ElasticPlasticLaw::Mode::Failed) st.vertical = vertical.fresh();
  if (st.torsional.mode != ElasticPlasticLaw::Mode::Failed) st.torsional = torsional.fresh();
}

void Anticlimber::transition(State& st, int index, double t, const Deformations& k, std::string& what) const {
  const auto add = [&what](const std::string& text) { what += (what.empty() ? "" : ", ") + text; };
  if (index == kContactRoot) {
    if (std::abs(k.offset) >= face_height) {  // the faces miss each other
      st.contact = Contact::Overridden;
      st.override_time = t;
      add("override");
      return;
    }
    st.contact = Contact::Engaged;
    seat_interlock(st, k);
    add("contact");
    return;
  }
  if (index == kOverrideRoot) {
    st.contact = Contact::Overridden;
    st.override_time = t;
    add("override");
    return;
  }
  const int direction = index / 3;
  const ElasticPlasticLaw& law = direction == 0 ? horizontal : (direction == 1 ? vertical : torsional);
  ElasticPlasticLaw::State& law_state = direction == 0 ? st.horizontal : (direction == 1 ? st.vertical : st.torsional);
  const std::string name = kDirections[direction];
  switch (law.leave(law_state, index % 3, k.d[direction])) {
    case ElasticPlasticLaw::Outcome::Yield: add(name + " yield"); break;
    case ElasticPlasticLaw::Outcome::Reloading:
      add(name + " reloading");
      if (direction == 0 && st.interlock_released) {
        seat_interlock(st, k);
        add("interlock re-seated");
      }
      break;
    case ElasticPlasticLaw::Outcome::Unloading:
      add(name + " unloading");
      if (direction == 0 && release_while_unloading) {
        st.interlock_released = true;
        add("interlock released");
      }
      break;
    case ElasticPlasticLaw::Outcome::Rupture:
      if (direction == 0) st.contact = Contact::Crushed;
      add(direction == 0 ? "crushing failure" : (direction == 1 ? "shear failure" : "bending failure"));
      break;
    case ElasticPlasticLaw::Outcome::Release:
      st.contact = Contact::Open;
      st.interlock_released = false;  // the next contact seats it afresh
      add("separation");
      break;
  }
}

void Anticlimber::settle(State& st, double t, const ElementState<double>& s, std::string& what) const {
  // Each pass makes one transition; every chain of them ends in a terminal or elastic mode
  // well within this bound.
  for (int pass = 0; pass < 4 * kRootCount; ++pass) {
    const Deformations k = deformations(st, s);
    double g[kRootCount];
    roots_of(st, k, g);
    int index = -1;
    for (int i = 0; i < kRootCount && index < 0; ++i)
      if (active(st, i) && g[i] < 0.0) index = i;
    if (index < 0) return;
    transition(st, index, t, k, what);
  }
}

void Anticlimber::initialize(const ElementState<double>& initial) {
  const std::string who = where().prefix() + "anticlimber '" + name() + "'";
  if (point_slot(0) == point_slot(1))
    throw InputError(who + ": both points are on the same body; put point 1 on one car end and point 2 on the other");
  if (!facing) {
    facing = 1.0;
    const double along = -kinematics(initial).horizontal;  // d . e1
    if (along == 0.0)
      throw InputError(who + ": the faces touch in the initial configuration, so which way they face is unknown; "
                             "give facing: 1 (body 1's face looks along its +x axis) or -1");
    facing = along > 0.0 ? 1.0 : -1.0;
  }
  const double gap = -kinematics(initial).horizontal;
  if (gap < 0.0)
    throw InputError(who + ": the faces overlap by " + std::to_string(-gap) +
                     " in the initial configuration; start them apart or just touching (there is no crush history to start from)");
  State& st = initial_state_;
  st = State{};
  st.contact = Contact::Open;
  st.horizontal = horizontal.fresh();
  st.vertical = vertical.fresh();
  st.torsional = torsional.fresh();
  const Deformations k = deformations(st, initial);
  if (gap == 0.0 && k.rate[0] > 0.0) {  // touching and closing: engaged from the start
    std::string what;
    transition(st, kContactRoot, 0.0, k, what);
    settle(st, 0.0, initial, what);
  }
}

void Anticlimber::roots_in(const State& st, const ElementState<double>& s, double* g) const {
  roots_of(st, deformations(st, s), g);
}

bool Anticlimber::commit_in(State& st, int index, int direction, double t, const ElementState<double>& s,
                            Event& event) const {
  if (direction > 0 || !active(st, index)) return false;
  const Deformations k = deformations(st, s);
  double g[kRootCount];
  roots_of(st, k, g);
  if (g[index] > 0.0) return false;  // an earlier commit at this instant already changed the mode
  const State before = st;
  std::string what;
  transition(st, index, t, k, what);
  // The event's value: the offset v for an override (also faces missing each other at
  // contact), else the deformation of the direction concerned (d_h for contact).
  const double value = (index == kOverrideRoot || (index == kContactRoot && overridden(st)))
                           ? k.offset
                           : k.d[index == kContactRoot ? 0 : index / 3];
  settle(st, t, s, what);
  // Contact seats the interlock at the faces' offset (every force starts at zero); yield,
  // unloading and reloading change slopes only; separation releases the faces at zero
  // horizontal force (IDA checks that the interlock's forces are zero there too). Override,
  // crushing, shear or bending failure and the interlock's release or re-seating are jumps.
  const auto ruptured = [](const State& x) {
    using M = ElasticPlasticLaw::Mode;
    return x.horizontal.mode == M::Failed || x.vertical.mode == M::Failed || x.torsional.mode == M::Failed;
  };
  const bool kink = (st.contact == Contact::Open || st.contact == Contact::Engaged) &&
                    st.interlock_released == before.interlock_released && ruptured(st) == ruptured(before);
  event = {what, value, kink ? EventKind::Kink : EventKind::Jump};
  return true;
}

double Anticlimber::potential_energy(const ElementState<double>& s) const {
  const State& st = mode_as<State>(s);
  if (st.contact != Contact::Engaged) return 0.0;
  const Deformations k = deformations(st, s);
  const double h = horizontal.elastic_energy(st.horizontal, k.d[0]);
  if (st.interlock_released) return h;
  return h + vertical.elastic_energy(st.vertical, k.d[1]) + torsional.elastic_energy(st.torsional, k.d[2]);
}

void Anticlimber::outputs(const ElementState<double>& s, const double*, double* out) const {
  const State& st = mode_as<State>(s);
  const Deformations k = deformations(st, s);
  const bool engaged = st.contact == Contact::Engaged, held = interlocked(st);
  out[0] = engaged ? horizontal.force(st.horizontal, k.d[0]) : 0.0;
  out[1] = held ? vertical.force(st.vertical, k.d[1]) : 0.0;
  out[2] = held ? torsional.force(st.torsional, k.d[2]) : 0.0;
  out[3] = k.d[0];
  out[4] = held ? k.d[1] : 0.0;
  out[5] = held ? k.d[2] : 0.0;
  out[6] = k.offset;
  out[7] = overridden(st) ? 1.0 : 0.0;
}

void register_anticlimber_elements(ElementRegistry& registry) {
  std::vector<ParameterSpec> parameters;
  for (const char* direction : kDirections) {
    const bool rotation = std::string(direction) == "torsional";
    const Unit slope = rotation ? Unit::MomentPerAngle : Unit::ForcePerLength;
    const Unit deflection = rotation ? Unit::Angle : Unit::Length;
    const std::string d = direction;
    parameters.push_back({d + "_elastic_stiffness", slope, required, Range::Positive, d + " elastic slope"});
    parameters.push_back({d + "_plastic_stiffness", slope, required, Range::NonNegative,
                          d + " slope after yield, below the elastic slope (0: perfectly plastic)"});
    parameters.push_back({d + "_yield_deflection", deflection, required, Range::Positive, d + " deflection at yield"});
    parameters.push_back({d + "_rupture_deflection", deflection,
                          optional(rotation || d == "vertical" ? "no rupture" : "length, else no rupture"),
                          Range::Positive,
                          d + " deflection at rupture (" +
                              (d == "horizontal" ? "crushing" : d == "vertical" ? "shear" : "bending") +
                              " failure), above the yield deflection"});
  }
  parameters.push_back({"face_height", Unit::Length, required, Range::Positive,
                        "height of each face; the faces override when their vertical offset reaches it"});
  parameters.push_back({"length", Unit::Length, optional("no bound on the crush"), Range::Positive,
                        "length of the anticlimber / end structure: bounds the horizontal rupture deflection"});
  parameters.push_back({"initial_misalignment", Unit::Length, default_value(0.0), Range::Any,
                        "vertical offset of the faces added to that of the points (face 2 above face 1 > 0)"});
  parameters.push_back({"misalignment_geometry", Unit::Choice, default_word("face"), Range::Any,
                        "face: face 2's centre is initial_misalignment above point 2 in body 2's frame (the forces act "
                        "there; the same as giving point 2 at the face centre); offset: the misalignment is only added "
                        "to the vertical offset (before issue 40; a constant offset then cancels in the interlock)",
                        Shape::Word});
  parameters.push_back({"facing", Unit::Choice, optional("the side of P2 at the start"), Range::Any,
                        "1: body 1's face looks along its +x axis, -1: along -x"});
  parameters.push_back({"interlock_while_unloading", Unit::Choice, default_word("hold"), Range::Any,
                        "hold: the vertical and torsional interlock holds while the horizontal law unloads; release: "
                        "it lets go then and re-seats at reloading",
                        Shape::Word});
  registry.add({kAnticlimberType, "15", 2, "P1 on body 1, P2 on body 2: the centres of the two anticlimber faces",
                "Two impacting anticlimber faces: measured in body 1's frame, open until the faces touch, then "
                "interlocked, with three independent bilinear elastic-plastic laws with kinematic hardening "
                "(horizontal in compression only, vertical and torsional both ways). Events for yield, unloading, "
                "reloading, separation, shear / crushing / bending failure (rupture deflections), and override "
                "when the vertical offset reaches the face height.",
                parameters,
                "horizontal_elastic_stiffness: 4.45e6\nhorizontal_plastic_stiffness: 20620\n"
                "horizontal_yield_deflection: 0.053\nvertical_elastic_stiffness: 175000\n"
                "vertical_plastic_stiffness: 1633\nvertical_yield_deflection: 0.2\nvertical_rupture_deflection: 5\n"
                "torsional_elastic_stiffness: 110800\ntorsional_plastic_stiffness: 25500\n"
                "torsional_yield_deflection: 0.001\nface_height: 6\nlength: 58.125\ninterlock_while_unloading: hold",
                [](ElementSpec& s) { return std::make_unique<Anticlimber>(s); }});
}

Anticlimber::State Anticlimber::stiffest_mode(const ElementState<double>& s) const {
  State stiffest = mode_as<State>(s);
  const Kinematics<double> k = kinematics(s);
  stiffest.contact = Contact::Engaged;
  stiffest.interlock_released = false;
  stiffest.horizontal = horizontal.fresh();
  stiffest.vertical = vertical.fresh();
  stiffest.torsional = torsional.fresh();
  stiffest.vertical_reference = k.vertical;
  stiffest.torsional_reference = k.rotation;
  return stiffest;
}

}  // namespace railcrash
