#include "railcrash/elements/beams.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace railcrash {

namespace {

/// What a beam's points-meet stop asks for.
const char* const kBeamAdvice =
    "A beam cannot be crushed through its length: give it a plastic_modulus above 0 (it then fractures at "
    "ultimate_stress), or model the crush with a crush_spring, or stop the motion first with a contact element";

BeamMaterial read_material(ElementSpec& spec) {
  ParameterReader& p = *spec.parameters;
  BeamMaterial m{};
  m.elastic_modulus = p.value("elastic_modulus");
  m.plastic_modulus = p.value("plastic_modulus");
  m.yield_stress = p.value("yield_stress");
  m.ultimate_stress = p.value("ultimate_stress");
  if (!(m.plastic_modulus < m.elastic_modulus))
    p.fail("plastic_modulus", "'plastic_modulus' (the tangent modulus after yield) must be less than 'elastic_modulus'");
  if (!(m.ultimate_stress > m.yield_stress))
    p.fail("ultimate_stress", "'ultimate_stress' must be greater than 'yield_stress'");
  return m;
}

/// int_0^1 f(s) ds by composite 5-point Gauss-Legendre, panels doubled until two
/// successive results agree to 1e-14 (f smooth and positive on [0, 1]).
template <class F>
double integrate(F f) {
  static const double node[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640};
  static const double weight[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665,
                                   0.2369268850561891};
  const auto rule = [&](int panels) {
    double sum = 0.0;
    const double h = 1.0 / panels;
    for (int i = 0; i < panels; ++i)
      for (int k = 0; k < 5; ++k) sum += weight[k] * f(h * (i + 0.5 + 0.5 * node[k]));
    return 0.5 * h * sum;
  };
  double previous = rule(1);
  for (int panels = 2; panels <= (1 << 16); panels *= 2) {
    const double next = rule(panels);
    if (std::abs(next - previous) <= 1e-14 * std::abs(next)) return next;
    previous = next;
  }
  return previous;
}

/// Section of a rectangle whose height and width vary linearly along the beam.
BeamSection tapered_section(double h1, double h2, double w1, double w2) {
  const auto height = [=](double s) { return h1 + (h2 - h1) * s; };
  const auto width = [=](double s) { return w1 + (w2 - w1) * s; };
  const auto inverse_i = [&](double s) {
    const double h = height(s);
    return 12.0 / (width(s) * h * h * h);
  };
  BeamSection section;
  section.axial_flexibility = integrate([&](double s) { return 1.0 / (height(s) * width(s)); });
  section.bending_flexibility = {integrate([&](double s) { return (1.0 - s) * (1.0 - s) * inverse_i(s); }),
                                 integrate([&](double s) { return s * (1.0 - s) * inverse_i(s); }),
                                 integrate([&](double s) { return s * s * inverse_i(s); })};
  section.yield_area = std::min(h1 * w1, h2 * w2);
  section.plastic_section_modulus = {w1 * h1 * h1 / 4.0, w2 * h2 * h2 / 4.0};
  return section;
}

const char* const kComponentName[3] = {"axial", "end 1", "end 2"};

// The elastic-mode yield root fires at |F - c p| = (1 + kYieldMargin) Y. Right after an
// unloading (a turning point: the flow rate is zero there) the yield function starts at zero
// and leaves it only quadratically; a rounding-level negative start would then look to IDA
// like a crossing right at the restart that it cannot separate from it ("root found at and
// very near t"). The margin keeps the root strictly positive at every restart; the yield
// level it shifts (1e-9 relative) is far below any tolerance a model runs at.
constexpr double kYieldMargin = 1e-9;

}  // namespace

// ---- the two section types ---------------------------------------------------------------

ElasticPlasticBeam::ElasticPlasticBeam(ElementSpec& spec) : BeamElement(spec, read_material(spec)) {
  ParameterReader& p = *spec.parameters;
  height = p.number("height");
  width = p.number("width");
  const std::optional<double> given_area = p.number("area");
  const std::optional<double> given_second_moment = p.number("second_moment");
  const std::optional<double> given_modulus = p.number("plastic_section_modulus");
  const bool rectangle = height || width;
  const bool properties = given_area || given_second_moment;
  if (rectangle && properties)
    p.fail(height ? "height" : "width",
           "give the section either as 'height' and 'width' or as 'area' and 'second_moment', not both");
  if (rectangle) {
    if (!height) p.fail("height", "missing 'height' (the section height in the plane of bending) next to 'width'");
    if (!width) p.fail("width", "missing 'width' (the section width) next to 'height'");
    area = *width * *height;
    second_moment = *width * *height * *height * *height / 12.0;
    plastic_section_modulus = *width * *height * *height / 4.0;
  } else {
    if (!given_area || !given_second_moment)
      p.fail(given_area ? "second_moment" : "area",
             "give the section as 'height' and 'width', or as 'area' and 'second_moment' (both)");
    area = *given_area;
    second_moment = *given_second_moment;
    plastic_section_modulus = std::sqrt(3.0 * area * second_moment) / 2.0;  // rectangle with the same A and I
  }
  if (given_modulus) plastic_section_modulus = *given_modulus;
  section_.axial_flexibility = 1.0 / area;
  section_.bending_flexibility = {1.0 / (3.0 * second_moment), 1.0 / (6.0 * second_moment), 1.0 / (3.0 * second_moment)};
  section_.yield_area = area;
  section_.plastic_section_modulus = {plastic_section_modulus, plastic_section_modulus};
}

TaperedBeam::TaperedBeam(ElementSpec& spec)
    : BeamElement(spec, read_material(spec)),
      height_1(spec.parameters->value("height_1")),
      height_2(spec.parameters->value("height_2")),
      width_1(spec.parameters->value("width_1")),
      width_2(spec.parameters->value("width_2")) {
  section_ = tapered_section(height_1, height_2, width_1, width_2);
}

// ---- the common law ----------------------------------------------------------------------

BeamElement::BeamElement(ElementSpec& spec, BeamMaterial beam_material)
    : HybridElement(spec.name, spec.type, spec.points, spec.where), material(beam_material) {}

void BeamElement::initialize(const ElementState<double>& initial) {
  if (point_slot(0) == point_slot(1))
    throw InputError(where().prefix() + type() + " '" + name() +
                     "': both points are on the same body; a beam connects two bodies (or a body and ground)");
  const auto k1 = static_cast<std::size_t>(point_slot(0));
  const auto k2 = static_cast<std::size_t>(point_slot(1));
  const Vec2<double> d = point_position(initial.q[k2], point(1).sx, point(1).sy) -
                         point_position(initial.q[k1], point(0).sx, point(0).sy);
  length_ = std::sqrt(dot(d, d));
  if (!(length_ > 0.0))
    throw InputError(where().prefix() + type() + " '" + name() +
                     "': its two points coincide in the initial configuration; a beam needs a length, move them apart");
  direction_ = {d.x / length_, d.y / length_};
  points_meet_.initialize(*this, initial);
  initial_angle_ = {initial.q[k1].theta, initial.q[k2].theta};
  for (std::size_t k = 0; k < 2; ++k) {  // u0 in each end body's frame: R(-theta_k(0)) u0
    const Vec2<double> u = rotate(-initial_angle_[k], direction_[0], direction_[1]);
    body_direction_[k] = {u.x, u.y};
  }

  const double e = material.elastic_modulus;
  axial_stiffness_ = e / (length_ * section_.axial_flexibility);
  const auto& f = section_.bending_flexibility;  // flexibility (L0 / E) [f0 -f1; -f1 f2]
  const double scale = e / (length_ * (f[0] * f[2] - f[1] * f[1]));
  bending_stiffness_ = {scale * f[2], scale * f[1], scale * f[0]};
  yield_ = {material.yield_stress * section_.yield_area, material.yield_stress * section_.plastic_section_modulus[0],
            material.yield_stress * section_.plastic_section_modulus[1]};
  const double ratio = material.plastic_modulus / (e - material.plastic_modulus);
  hardening_ = {axial_stiffness_ * ratio, bending_stiffness_[0] * ratio, bending_stiffness_[2] * ratio};
}

void BeamElement::evaluate(const ElementState<double>& s, std::array<double, 3>& force, std::array<double, 3>& offset,
                           std::array<double, 3>* offset_rate, std::array<double, 3>* strain,
                           Kinematics<double>* chord, std::array<double, 3>* force_rate) const {
  // One pass with a single directional derivative along the velocities gives the rates.
  using D = Dual<double, 1>;
  ElementState<D> sd;
  for (std::size_t k = 0; k < 2; ++k) {
    const double* q[3] = {&s.q[k].x, &s.q[k].y, &s.q[k].theta};
    const double* v[3] = {&s.v[k].x, &s.v[k].y, &s.v[k].theta};
    D* out[3] = {&sd.q[k].x, &sd.q[k].y, &sd.q[k].theta};
    for (int c = 0; c < 3; ++c) {
      *out[c] = D(*q[c]);
      out[c]->grad[0] = *v[c];
    }
    sd.rotation[k] = rotation_of(sd.q[k].theta, s.rotation[k]);
  }
  sd.mode = s.mode;
  const Kinematics<D> kd = kinematics(sd);
  const std::array<D, 3>& x = kd.strain;
  const std::array<D, 3> p = plastic_offsets(mode_as<State>(s), x);
  const std::array<D, 3> r = resultants(x, p);
  for (std::size_t k = 0; k < 3; ++k) {
    force[k] = r[k].value;
    offset[k] = p[k].value;
    if (offset_rate) (*offset_rate)[k] = p[k].grad[0];
    if (force_rate) (*force_rate)[k] = r[k].grad[0];
    if (strain) (*strain)[k] = x[k].value;
  }
  if (chord) {
    chord->d = {kd.d.x.value, kd.d.y.value};
    chord->length = kd.length.value;
    for (std::size_t k = 0; k < 3; ++k) chord->strain[k] = x[k].value;
  }
}

double BeamElement::stress(const std::array<double, 3>& force) const {
  return std::max({std::abs(force[0]) / section_.yield_area, std::abs(force[1]) / section_.plastic_section_modulus[0],
                   std::abs(force[2]) / section_.plastic_section_modulus[1]});
}

void BeamElement::roots_in(const State& st, const ElementState<double>& s, double* g) const {
  g[0] = g[1] = g[2] = g[3] = g[kPointsMeetRoot] = 1.0;
  if (st.failed) return;
  std::array<double, 3> force{}, offset{}, rate{}, force_rate{};
  Kinematics<double> chord;
  evaluate(s, force, offset, &rate, nullptr, &chord, &force_rate);
  roots_from(st, force, offset, rate, force_rate, g);
  g[kPointsMeetRoot] = points_meet_.gap(*this, s, length_, chord.d, chord.length);
}

void BeamElement::roots_from(const State& st, const std::array<double, 3>& force, const std::array<double, 3>& offset,
                             const std::array<double, 3>& rate, const std::array<double, 3>& force_rate, double* g) const {
  for (std::size_t k = 0; k < 3; ++k) {
    const int sign = st.sign[k];
    if (sign != 0) {
      g[k] = sign * rate[k];  // the plastic flow rate
      continue;
    }
    const double excess = force[k] - hardening_[k] * offset[k];  // [force] F_k - c_k p_k
    const double growth = (excess < 0.0 ? -force_rate[k] : force_rate[k]) / yield_[k];  // [1/time] d|F_k - c_k p_k|/dt / Y_k
    g[k] = position_root_moving_on(1.0 + kYieldMargin - std::abs(excess) / yield_[k], growth);
  }
  g[3] = 1.0 - stress(force) / material.ultimate_stress;
}

bool BeamElement::commit_in(State& st, int index, int direction, double t, const ElementState<double>& s,
                            Event& event) const {
  if (st.failed || direction > 0) return false;
  if (points_meet_.met(*this, s, length_, index, kPointsMeetRoot, direction))
    points_meet_.stop(*this, t, s, length_, "", kBeamAdvice, "is crushed through its whole length", "an initial length");
  if (index == kPointsMeetRoot) return false;
  std::array<double, 3> force{}, offset{};
  evaluate(s, force, offset);
  if (index == 3) {
    st.failed = true;
    event = {"fracture", stress(force)};
    return true;
  }
  const auto k = static_cast<std::size_t>(index);
  const std::string component = kComponentName[k];
  if (st.sign[k] == 0) {
    st.sign[k] = force[k] - hardening_[k] * offset[k] > 0.0 ? 1 : -1;
    if (k == 0)
      event = {st.sign[k] > 0 ? "axial yield in tension" : "axial yield in compression", force[k], EventKind::Kink};
    else
      event = {"plastic hinge at " + component, force[k], EventKind::Kink};
  } else {
    st.offset[k] = offset[k];
    st.sign[k] = 0;
    event = {k == 0 ? std::string("axial unloading") : "hinge at " + component + " unloading", force[k], EventKind::Kink};
  }
  return true;
}

BeamElement::State BeamElement::stiffest_mode(const ElementState<double>& s) const {
  State elastic = mode_as<State>(s);
  elastic.sign = {0, 0, 0};
  elastic.failed = false;
  return elastic;
}

double BeamElement::potential_energy(const ElementState<double>& s) const {
  const State& st = mode_as<State>(s);
  if (st.failed) return 0.0;
  const std::array<double, 3> x = kinematics(s).strain;
  const std::array<double, 3> p = plastic_offsets(st, x);
  const std::array<double, 3> r = resultants(x, p);
  double energy = 0.0;
  for (std::size_t k = 0; k < 3; ++k) energy += 0.5 * r[k] * (x[k] - p[k]);
  return energy;
}

std::vector<std::string> BeamElement::output_names() const {
  return {"force",           "moment_1",          "moment_2",          "stretch", "rotation_1", "rotation_2",
          "plastic_stretch", "hinge_rotation_1", "hinge_rotation_2", "stress",  "failed"};
}

void BeamElement::outputs(const ElementState<double>& s, const double*, double* out) const {
  std::array<double, 3> force{}, offset{}, x{};
  evaluate(s, force, offset, nullptr, &x);
  outputs_from(mode_as<State>(s), force, offset, x, out);
}

void BeamElement::roots_and_outputs(double, const ElementState<double>& s, const double*, double* g, double* out) const {
  const State& st = mode_as<State>(s);
  std::array<double, 3> force{}, offset{}, rate{}, force_rate{};
  Kinematics<double> chord;
  evaluate(s, force, offset, &rate, nullptr, &chord, &force_rate);
  if (g != nullptr) {
    g[0] = g[1] = g[2] = g[3] = g[kPointsMeetRoot] = 1.0;
    if (!st.failed) {
      roots_from(st, force, offset, rate, force_rate, g);
      g[kPointsMeetRoot] = points_meet_.gap(*this, s, length_, chord.d, chord.length);
    }
  }
  if (out != nullptr) outputs_from(st, force, offset, chord.strain, out);
}

void BeamElement::force_roots_and_outputs(double t, const ElementState<double>& s, const double*,
                                          std::array<Pose<double>, 2>& f, double* g, double* out) const {
  if (g == nullptr && out == nullptr) {
    add_force(t, s, f);
    return;
  }
  const State& st = mode_as<State>(s);
  std::array<double, 3> force{}, offset{}, rate{}, force_rate{};
  Kinematics<double> chord;
  evaluate(s, force, offset, &rate, nullptr, &chord, &force_rate);
  if (g != nullptr) {
    g[0] = g[1] = g[2] = g[3] = g[kPointsMeetRoot] = 1.0;
    if (!st.failed) {
      roots_from(st, force, offset, rate, force_rate, g);
      g[kPointsMeetRoot] = points_meet_.gap(*this, s, length_, chord.d, chord.length);
    }
  }
  if (out != nullptr) outputs_from(st, force, offset, chord.strain, out);
  // The dual pass's kinematics values are the double pass's, operation for operation. Its
  // offsets and resultants are not (a dual divided by a number is multiplied by the inverse),
  // so those few operations are redone in double: force_law's force, bit for bit.
  if (!st.failed) apply_resultants(s, chord.d, chord.length, resultants(chord.strain, plastic_offsets(st, chord.strain)), f);
}

void BeamElement::outputs_from(const State& st, std::array<double, 3> force, const std::array<double, 3>& offset,
                               const std::array<double, 3>& x, double* out) const {
  if (st.failed) force = {0.0, 0.0, 0.0};
  for (std::size_t k = 0; k < 3; ++k) {
    out[k] = force[k];
    out[3 + k] = x[k];
    out[6 + k] = offset[k];
  }
  out[9] = stress(force);
  out[10] = st.failed ? 1.0 : 0.0;
}

namespace {

std::vector<ParameterSpec> material_specs() {
  return {{"elastic_modulus", Unit::Stress, required, Range::Positive, "Young's modulus E"},
          {"plastic_modulus", Unit::Stress, required, Range::NonNegative, "tangent modulus after yield, below E"},
          {"yield_stress", Unit::Stress, required, Range::Positive, "stress at which the section yields"},
          {"ultimate_stress", Unit::Stress, required, Range::Positive,
           "stress at which the beam fractures, above yield_stress"}};
}

std::vector<ParameterSpec> with_material(const std::vector<ParameterSpec>& section) {
  std::vector<ParameterSpec> all = material_specs();
  all.insert(all.end(), section.begin(), section.end());
  return all;
}

const char* const kBeamPoints = "P1 on body 1, P2 on body 2: the beam's ends, rigidly attached to their bodies";
const char* const kBeamLaw =
    "co-rotational planar beam rigidly attached to both bodies, axial force N = k_a (e - e_p), end moments "
    "[M1; M2] = K_b (phi - phi_p); axial yield at yield_stress times the area, end hinges at yield_stress times "
    "the plastic section modulus, kinematic hardening with plastic_modulus, elastic unloading; fracture when "
    "|N| / A or |M| / Z reaches ultimate_stress. Its ends meeting (within 1e-3 of its initial length) or passing "
    "each other stops the run, naming it.";
const char* const kBeamMaterialExample =
    "elastic_modulus: 2.0e11\nplastic_modulus: 2.0e9\nyield_stress: 2.5e8\nultimate_stress: 4.0e8\n";

}  // namespace

void register_beams_elements(ElementRegistry& registry) {
  registry.add(
      {"elastic_plastic_beam", "5", 2, kBeamPoints,
       "Elastic-plastic beam of uniform section: " + std::string(kBeamLaw) +
           " For the uniform section k_a = E A / L0, K_b = E I / L0 [4 2; 2 4].",
       with_material(
           {{"height", Unit::Length, optional("give area and second_moment instead"), Range::Positive,
             "height of a rectangular section (in the plane of bending), with width"},
            {"width", Unit::Length, optional("give area and second_moment instead"), Range::Positive,
             "width of a rectangular section, with height"},
            {"area", Unit::Area, optional("from height and width"), Range::Positive,
             "section area, with second_moment"},
            {"second_moment", Unit::SecondMoment, optional("from height and width"), Range::Positive,
             "second moment of area, with area"},
            {"plastic_section_modulus", Unit::SectionModulus,
             optional("width height^2 / 4, or that of the rectangle with the same area and second moment"),
             Range::Positive, "plastic section modulus Z (end hinges yield at yield_stress Z)"}}),
       std::string(kBeamMaterialExample) + "height: 0.1\nwidth: 0.05",
       [](ElementSpec& s) { return std::make_unique<ElasticPlasticBeam>(s); }});
  registry.add({"tapered_beam", "22", 2, kBeamPoints,
                "Elastic-plastic beam of tapered section: " + std::string(kBeamLaw) +
                    " The rectangular section's height and width vary linearly from end 1 to end 2; the stiffness "
                    "comes from the flexibility integrals of the taper.",
                with_material({{"height_1", Unit::Length, required, Range::Positive, "section height at end 1"},
                               {"height_2", Unit::Length, required, Range::Positive, "section height at end 2"},
                               {"width_1", Unit::Length, required, Range::Positive, "section width at end 1"},
                               {"width_2", Unit::Length, required, Range::Positive, "section width at end 2"}}),
                std::string(kBeamMaterialExample) + "height_1: 0.1\nheight_2: 0.05\nwidth_1: 0.05\nwidth_2: 0.05",
                [](ElementSpec& s) { return std::make_unique<TaperedBeam>(s); }});
}

}  // namespace railcrash
