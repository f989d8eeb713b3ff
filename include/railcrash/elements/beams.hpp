// Elastic-plastic beams (report Table 2, types 5 and 22; Section 3.1: "elastic-plastic
// beams ... rigidly connected to the masses ... allow large deflections, axial crushing and
// large plastic deformation in bending").
//
// elastic_plastic_beam (5)  a planar beam from point P1 (body 1) to point P2 (body 2),
//                           rigidly attached to both bodies: its end tangents turn with them.
// tapered_beam (22)         the same with a rectangular section whose height and width vary
//                           linearly from end 1 to end 2.
//
// Kinematics (co-rotational: the chord P1 -> P2 carries the beam's rigid motion, so rigid
// rotations of any size leave it unstressed). With d = r2 - r1, L = |d|, L0 = the initial
// chord length, u0 = the initial chord direction and t_i = R(theta_i - theta_i(0)) u0 the
// end-i tangent carried by its body:
//   stretch      e    = L - L0
//   rotation_i   phi_i = angle from the chord d to t_i = atan2(d x t_i, d . t_i)
// (zero in the initial configuration: the beam starts straight and unstressed).
//
// Resultants (x = (e, phi_1, phi_2), plastic offsets p = (e_p, phi_1p, phi_2p)):
//   axial force  N = k_a (e - e_p)                                    (tension > 0)
//   end moments  [M_1; M_2] = K_b [phi_1 - phi_1p; phi_2 - phi_2p]    (conjugate to phi_i)
// with k_a = 1 / int_0^L0 dx / (E A) and K_b the inverse of the flexibility matrix
//   (1/E) [ int (1-s)^2 / I dx,  -int s(1-s) / I dx ;  -int s(1-s) / I dx,  int s^2 / I dx ],
// s = x / L0 (simply supported beam with end moments: no shear deformation). For a uniform
// beam k_a = E A / L0 and K_b = (E I / L0) [4 2; 2 4] (Euler-Bernoulli end moments).
// The elastic energy is U = k_a (e - e_p)^2 / 2 + (phi - phi_p)^T K_b (phi - phi_p) / 2 and
// the generalized forces are exactly -(N de/dq + M_1 dphi_1/dq + M_2 dphi_2/dq):
//   force on P2 = -N d / L + (M_1 + M_2) perp(d) / L^2,  force on P1 = minus that,
//   moment on body 1 = -M_1, on body 2 = -M_2           (perp(d) = (-d_y, d_x))
// so the element is in equilibrium (forces and moments sum to zero) in every state.
//
// Plasticity: three independent components (N-M interaction is ignored, as in a lumped
// hinge model; a crash engineer sizing the beams should know that a combined axial load
// and bending moment yields later here than in the section), each elastic, or plastic in
// the + or - direction, with linear kinematic hardening and elastic unloading:
//   axial           yields at |N - c_a e_p| = N_y = yield_stress * A_min
//   hinge at end i  yields at |M_i - c_i phi_ip| = M_pi = yield_stress * Z_i
// While component k is plastic in direction s_k its offset p_k is not history but solves
//   F_k(x, p) = s_k Y_k + c_k p_k        (F = (N, M_1, M_2), Y = (N_y, M_p1, M_p2))
// (a 1x1 or 2x2 linear system, smooth in the mode); when it unloads the offset reached is
// stored as history. The hardening coefficients
//   c_a = k_a E_t / (E - E_t),  c_i = K_b,ii E_t / (E - E_t)   (E_t = plastic_modulus)
// make the plastic slope the elastic one times E_t / E: axially dN/de = k_a E_t / E (the
// material's tangent modulus over the whole length), and for a hinge dM_i/dphi_i =
// K_b,ii E_t / E with the far end held (as if the whole beam bent with the tangent
// modulus). E_t = 0 gives perfectly plastic yield and hinges.
// The plastic hinge itself is rigid-plastic (elastic bending stays in K_b): the section's
// first-fibre yield at M = yield_stress * I / c is not modelled, only the full hinge at M_p.
//
// Fracture: the beam fails when the axial stress |N| / A_min or the hinge stress |M_i| / Z_i
// (the stress of the fully plastic hinge, yield_stress at M_p and growing with hardening)
// reaches ultimate_stress. A failed beam carries nothing; the elastic energy it held at
// fracture is released (it shows up as dissipated energy).
//
// Points meeting: a beam crushed axially until its ends come within 1e-3 L0 of each other, or
// pass each other, stops the run with a message naming it (PointsMeet, springs.hpp): the chord
// has no direction there, and a step that carried one end past the other would turn its axial
// force and end moments around. (With plastic_modulus > 0 the axial stress reaches
// ultimate_stress and the beam fractures first; a perfectly plastic beam, plastic_modulus 0,
// crushes at its yield force without end.)
//
// Modes and events (5 root functions; an inactive one returns 1):
//   g_k, k = 0 axial, 1 hinge 1, 2 hinge 2:
//     elastic   1 + 1e-9 - |F_k - c_k p_k| / Y_k  goes negative while |F_k - c_k p_k| grows
//               along the velocities (position_root_moving_on, hybrid.hpp): yield (event "axial
//               yield in tension|compression" with N, "plastic hinge at end i" with M_i).
//               Moving back it stays positive: the constraints' position correction (GGL) can
//               carry a section past its yield surface while its velocities unload it, and the
//               plastic mode's own root then unloaded it at once (10,000 alternating mode
//               changes at one instant on scenario1_report_car's draw bar at rtol 2e-3)
//     plastic   s_k dp_k/dt (the plastic flow rate) goes negative: unloading (event
//               "axial unloading" / "hinge at end i unloading"), p_k is stored
//   g_3         1 - max(|N| / (sigma_u A_min), |M_i| / (sigma_u Z_i)) goes negative: "fracture"
//   g_4         the ends' distance less 1e-3 L0 (PointsMeet::gap): the run stops
// The potential energy is the elastic energy U above (what unloading would give back); the
// rest of the work done on the beam is dissipated by plastic flow (and fracture).
//
// Sections
//   elastic_plastic_beam: a rectangle `height` x `width` (height in the plane of bending:
//     A = w h, I = w h^3 / 12, Z = w h^2 / 4), or `area` and `second_moment` (the report's
//     beams are boxes with the area and second moment of the member they represent, Section
//     3.1); then Z defaults to that of the rectangle with the same A and I, h = sqrt(12 I / A):
//     Z = A h / 4 = sqrt(3 A I) / 2, unless `plastic_section_modulus` is given.
//   tapered_beam: h and w linear from (height_1, width_1) at P1 to (height_2, width_2) at P2;
//     k_a and K_b from the flexibility integrals above by composite Gauss-Legendre
//     quadrature refined until it converges to 1e-14 (the integrands are smooth and
//     positive); axial yield and fracture use the smaller end area (the area, a product of
//     two positive linear functions, is smallest at an end); hinge i uses Z_i of end i.
//
// Report values (Tables 5 and 8, in-lbf-s units; the scan is partly garbled):
//   Beam type 1: E = 1e7 psi (read from "1 x 10^' psi": the same aluminium as type 2, whose
//     values 20,000 / 60,000 psi it shares), E_t = 20,000 psi, yield 60,000 psi, ultimate
//     100,000 psi (Table 8 prints "psf"), height 19.55 in, width 0.676 in.
//   Beam type 2: E = 1e7 psi, E_t = 20,000 psi, yield 60,000 psi, ultimate 100,000 psi,
//     height 9.790 in, width 2.082 in.
//   Beam type 3: E = 3e7 psi, E_t = 180,000 psi, yield 100,000 psi, ultimate 150,000 psi,
//     height 10.360 in, width 0.776 in.
//   Tapered beam (draw bar): E = 3e7 psi, E_t = 180,000 psi, yield 100,000 psi, ultimate
//     200,000 psi, height_1 (end K) 3.273 in, width_1 2.830 in, height_2 (end l) 5.475 in,
//     width_2 1.827 in. Table 5 lists all four with their labels; Table 8 drops width end K
//     and prints 3.475 for the end-l height: read as an OCR 5 -> 3 slip, Table 5 kept.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "railcrash/elements/hybrid.hpp"
#include "railcrash/elements/springs.hpp"
#include "railcrash/model/element.hpp"
#include "railcrash/model/element_registry.hpp"

namespace railcrash {

/// Material of a beam (report Tables 5 and 8).
struct BeamMaterial {
  double elastic_modulus;  // [force/length^2] E
  double plastic_modulus;  // [force/length^2] E_t, tangent modulus after yield, 0 <= E_t < E
  double yield_stress;     // [force/length^2]
  double ultimate_stress;  // [force/length^2] > yield_stress: fracture
};

/// What the element needs to know of its section along the length (s = x / L0 in [0, 1]).
struct BeamSection {
  double axial_flexibility = 0.0;                 // [1/length^2] int_0^1 ds / A(s)
  std::array<double, 3> bending_flexibility{};    // [1/length^4] int (1-s)^2/I, int s(1-s)/I, int s^2/I
  double yield_area = 0.0;                        // [length^2] A_min: axial yield and fracture
  std::array<double, 2> plastic_section_modulus{};  // [length^3] Z at end 1 and end 2
};

/// Both beam types: the co-rotational elastic-plastic law above. The section comes from
/// the derived type's parameters.
class BeamElement : public HybridElement<BeamElement> {
 public:
  BeamMaterial material;

  /// Component k: 0 axial, 1 hinge at end 1, 2 hinge at end 2.
  struct State {
    std::array<int, 3> sign{0, 0, 0};        // 0 elastic, +1 / -1 plastic in that direction
    std::array<double, 3> offset{0, 0, 0};   // [length, rad, rad] stored plastic offsets p_k
    bool failed = false;
  };
  RAILCRASH_ELEMENT_MODE(State, State{})

  // Derived in initialize() from the section and the initial chord length L0.
  double initial_length() const { return length_; }          // [length] L0
  double axial_stiffness() const { return axial_stiffness_; }  // [force/length] k_a
  /// K_b entries k11, k12, k22 [moment/rad].
  const std::array<double, 3>& bending_stiffness() const { return bending_stiffness_; }
  /// Yield levels N_y [force], M_p1, M_p2 [moment].
  const std::array<double, 3>& yield_levels() const { return yield_; }
  /// Hardening coefficients c_a [force/length], c_1, c_2 [moment/rad].
  const std::array<double, 3>& hardening() const { return hardening_; }
  const BeamSection& section() const { return section_; }

  /// Deformations of the chord frame.
  template <class T>
  struct Kinematics {
    Vec2<T> d;                // r2 - r1
    T length;                 // L
    std::array<T, 3> strain;  // e, phi_1, phi_2
  };

  template <class T>
  Kinematics<T> kinematics(const ElementState<T>& s) const {
    const auto k1 = static_cast<std::size_t>(point_slot(0));
    const auto k2 = static_cast<std::size_t>(point_slot(1));
    const PointRef& p1 = point(0);
    const PointRef& p2 = point(1);
    Kinematics<T> k;
    k.d = point_position(s.q[k2], s.rotation[k2], p2.sx, p2.sy) - point_position(s.q[k1], s.rotation[k1], p1.sx, p1.sy);
    k.length = sqrt(dot(k.d, k.d));
    k.strain[0] = k.length - length_;
    // t_k = R(theta_k - theta_k(0)) u0, written R(theta_k) (R(-theta_k(0)) u0) so the end
    // bodies' rotations serve (no further cos and sin per evaluation).
    const Vec2<T> t1 = rotate(s.rotation[k1], body_direction_[0][0], body_direction_[0][1]);
    const Vec2<T> t2 = rotate(s.rotation[k2], body_direction_[1][0], body_direction_[1][1]);
    k.strain[1] = atan2(cross(k.d, t1), dot(k.d, t1));
    k.strain[2] = atan2(cross(k.d, t2), dot(k.d, t2));
    return k;
  }

  /// Plastic offsets in mode st: stored for elastic components, solved from the yield
  /// conditions for plastic ones.
  template <class T>
  std::array<T, 3> plastic_offsets(const State& st, const std::array<T, 3>& x) const {
    const std::array<int, 3>& sign = st.sign;
    std::array<T, 3> p{T(st.offset[0]), T(st.offset[1]), T(st.offset[2])};
    if (sign[0] != 0) p[0] = (axial_stiffness_ * x[0] - sign[0] * yield_[0]) / (axial_stiffness_ + hardening_[0]);
    const double k11 = bending_stiffness_[0], k12 = bending_stiffness_[1], k22 = bending_stiffness_[2];
    const double d11 = k11 + hardening_[1], d22 = k22 + hardening_[2];
    if (sign[1] != 0 && sign[2] != 0) {
      // [d11 k12; k12 d22] p = K_b phi - s Y
      const T r1 = k11 * x[1] + k12 * x[2] - sign[1] * yield_[1];
      const T r2 = k12 * x[1] + k22 * x[2] - sign[2] * yield_[2];
      const double det = d11 * d22 - k12 * k12;
      p[1] = (d22 * r1 - k12 * r2) / det;
      p[2] = (d11 * r2 - k12 * r1) / det;
    } else if (sign[1] != 0) {
      p[1] = (k11 * x[1] + k12 * (x[2] - p[2]) - sign[1] * yield_[1]) / d11;
    } else if (sign[2] != 0) {
      p[2] = (k22 * x[2] + k12 * (x[1] - p[1]) - sign[2] * yield_[2]) / d22;
    }
    return p;
  }

  /// Resultants N, M_1, M_2 at deformation x with plastic offsets p.
  template <class T>
  std::array<T, 3> resultants(const std::array<T, 3>& x, const std::array<T, 3>& p) const {
    const T b1 = x[1] - p[1], b2 = x[2] - p[2];
    return {axial_stiffness_ * (x[0] - p[0]), bending_stiffness_[0] * b1 + bending_stiffness_[1] * b2,
            bending_stiffness_[1] * b1 + bending_stiffness_[2] * b2};
  }

  template <class T>
  void force_law(double /*t*/, const ElementState<T>& s, std::array<Pose<T>, 2>& f) const {
    const State& st = mode_as<State>(s);
    if (st.failed) return;
    const Kinematics<T> k = kinematics(s);
    apply_resultants(s, k.d, k.length, resultants(k.strain, plastic_offsets(st, k.strain)), f);
  }

  /// The generalized forces of resultants r = (N, M_1, M_2) on a chord d of length L.
  template <class T>
  void apply_resultants(const ElementState<T>& s, const Vec2<T>& d, const T& length, const std::array<T, 3>& r,
                        std::array<Pose<T>, 2>& f) const {
    // force on P2 = -N d / L + (M_1 + M_2) perp(d) / L^2
    const T along = -r[0] / length;
    const T across = (r[1] + r[2]) / (length * length);
    apply_line_force(*this, s, Vec2<T>{along * d.x - across * d.y, along * d.y + across * d.x}, f);
    f[static_cast<std::size_t>(point_slot(0))].theta -= r[1];
    f[static_cast<std::size_t>(point_slot(1))].theta -= r[2];
  }

  void initialize(const ElementState<double>& initial) override;
  bool applies_moment() const override { return true; }
  int root_count() const override { return 5; }
  static constexpr int kPointsMeetRoot = 4;
  void roots_in(const State& st, const ElementState<double>& s, double* g) const;
  bool commit_in(State& st, int index, int direction, double t, const ElementState<double>& s, Event& event) const;
  bool failed(const void* mode) const override { return static_cast<const State*>(mode)->failed; }
  /// Elastic in every component (plastic slopes are E_t / E times smaller).
  State stiffest_mode(const ElementState<double>& s) const;
  double potential_energy(const ElementState<double>& s) const override;
  std::vector<std::string> output_names() const override;
  void outputs(const ElementState<double>& s, const double* lambda, double* out) const override;
  /// One evaluation of the law for both (the step sweep's): a third of the beam's work there.
  void roots_and_outputs(double t, const ElementState<double>& s, const double* lambda, double* g,
                         double* out) const override;
  /// The same evaluation gives the force too (the energy rates' and Euler's sweep).
  void force_roots_and_outputs(double t, const ElementState<double>& s, const double* lambda,
                               std::array<Pose<double>, 2>& f, double* g, double* out) const override;

 protected:
  BeamElement(ElementSpec& spec, BeamMaterial beam_material);
  /// Set by the derived constructor.
  BeamSection section_;

 private:
  /// Resultants F and offsets p at state s, and (when given) dp/dt along s.v, the
  /// deformations x (stretch, end rotations), the chord (d, L; as kinematics() gives them) and
  /// dF/dt along s.v.
  void evaluate(const ElementState<double>& s, std::array<double, 3>& force, std::array<double, 3>& offset,
                std::array<double, 3>* offset_rate = nullptr, std::array<double, 3>* strain = nullptr,
                Kinematics<double>* chord = nullptr, std::array<double, 3>* force_rate = nullptr) const;
  /// The roots in mode st (not failed) from an evaluation at the state.
  void roots_from(const State& st, const std::array<double, 3>& force, const std::array<double, 3>& offset,
                  const std::array<double, 3>& offset_rate, const std::array<double, 3>& force_rate, double* g) const;
  /// The outputs in mode st from an evaluation at the state.
  void outputs_from(const State& st, std::array<double, 3> force, const std::array<double, 3>& offset,
                    const std::array<double, 3>& strain, double* out) const;
  /// Largest of |N| / A_min, |M_i| / Z_i [force/length^2].
  double stress(const std::array<double, 3>& force) const;

  PointsMeet points_meet_;                    // the ends meeting (root kPointsMeetRoot)
  double length_ = 0.0;                       // [length] L0
  std::array<double, 2> direction_{1.0, 0.0}; // u0, initial chord direction
  std::array<double, 2> initial_angle_{};     // [rad] theta of the body of P1, P2 at t = 0
  std::array<std::array<double, 2>, 2> body_direction_{};  // u0 in the frame of P1's, P2's body at t = 0
  double axial_stiffness_ = 0.0;              // [force/length]
  std::array<double, 3> bending_stiffness_{}; // [moment/rad] k11, k12, k22
  std::array<double, 3> yield_{};             // [force, moment, moment]
  std::array<double, 3> hardening_{};         // [force/length, moment/rad, moment/rad]
};

/// Report type 5: uniform section.
class ElasticPlasticBeam : public BeamElement {
 public:
  explicit ElasticPlasticBeam(ElementSpec& spec);
  std::optional<double> height;   // [length] rectangle, in the plane of bending
  std::optional<double> width;    // [length] rectangle, out of the plane
  double area;                    // [length^2] given, or width * height
  double second_moment;           // [length^4] given, or width * height^3 / 12
  double plastic_section_modulus; // [length^3] given, or width * height^2 / 4, or sqrt(3 A I) / 2
};

/// Report type 22: rectangular section, height and width linear from end 1 to end 2.
class TaperedBeam : public BeamElement {
 public:
  explicit TaperedBeam(ElementSpec& spec);
  double height_1;  // [length] at P1
  double height_2;  // [length] at P2
  double width_1;   // [length] at P1
  double width_2;   // [length] at P2
};

}  // namespace railcrash
