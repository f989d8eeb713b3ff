// Unilateral contact of a body point with a fixed ground surface: `contact` (barriers,
// stops; not in the 1980 report) and `wheel_rail` (report type 18).
//
// Geometry. The point r (the element's single point) against
//   a line   through `point` with unit normal n (`normal`, pointing to the free side):
//            gap g = n . (r - point)
//   a circle `center`, `radius` R; outside contact (default) g = |r - c| - R, n = (r - c)/|r - c|;
//            `inside: true` (the point moves inside a concave surface) g = R - |r - c|, n = -(r - c)/|r - c|
// wheel_rail: the point is the wheel centre, the rail the line y = rail_height + wheel_radius
// (normal +y), i.e. g = y - rail_height - wheel_radius.
// Penetration d = -g, its rate d' = -n . r'. Tangent t = (-n_y, n_x), slip speed v_t = t . r'.
//
// Law while in contact (modes below):
//   normal force  N = k1 d                          (d <= d_L)
//                   = k1 d_L + k2 (d - d_L)         (d >  d_L)      plus damping c d'
//   friction      F_t = -mu N tanh(v_t / v_f)   (Coulomb, regularized below the slip speed v_f)
//   force on the point: N n + F_t t
// `contact`: one slope (k1 = k2 = stiffness, no d_L); wheel_rail: stiffness below / above the
// breakpoint d_L (report: "two slopes (below / above dL)"), braking / rolling friction
// coefficient mu.
// Modes and their roots (each change is a located event):
//   open       (d <= 0)           no force;        leaves when d rises through 0 -> contact
//   contact, segment 1 or 2       the law above;   leaves when d falls through 0 (lift-off),
//                                                  N falls through 0 (the damper would pull:
//                                                  -> released), d crosses d_L (segment)
//   released   (d > 0, N < 0)     no force;        leaves when N rises through 0 (contact) or d
//                                                  falls through 0 (open)
// Elastic energy: the spring part of N integrated over d in contact; none when open/released.
#pragma once

#include <optional>

#include "railcrash/elements/hybrid.hpp"
#include "railcrash/model/element.hpp"
#include "railcrash/model/element_registry.hpp"

namespace railcrash {

class SurfaceContact : public HybridElement<SurfaceContact> {
 public:
  /// Reads the common parameters; `wheel_rail` selects the wheel-rail form of the surface.
  SurfaceContact(ElementSpec& spec, bool wheel_rail);

  enum class Surface { Line, Circle };
  Surface surface = Surface::Line;
  double px = 0.0, py = 0.0;      // [length] line: a point on it; circle: centre
  double nx = 0.0, ny = 1.0;      // line: unit normal toward the free side
  double radius = 0.0;            // [length] circle radius
  bool inside = false;            // circle: the point moves inside it
  double stiffness;               // [force/length] k1
  double stiffness_above;         // [force/length] k2 (= k1 for `contact`)
  double breakpoint;              // [length] d_L (infinite for `contact`)
  double damping;                 // [force*time/length] c
  double friction;                // [-] mu
  double friction_velocity;       // [length/time] v_f
  double friction_slip_velocity() const override { return friction > 0.0 ? friction_velocity : 0.0; }

  enum class Mode { Open, Contact, Released };
  struct State {
    Mode mode = Mode::Open;
    int segment = 0;  // contact: 0 below d_L, 1 above
  };
  RAILCRASH_ELEMENT_MODE(State, initial_state_)

  /// Penetration d and its rate d' at the point, and the unit normal / tangent there.
  template <class T>
  struct Kinematics {
    T penetration, rate, slip;
    Vec2<T> normal, tangent;
  };
  template <class T>
  Kinematics<T> kinematics(const ElementState<T>& s) const {
    const auto k = static_cast<std::size_t>(point_slot(0));
    const PointRef& p = point(0);
    const Vec2<T> r = point_position(s.q[k], s.rotation[k], p.sx, p.sy);
    const Vec2<T> v = point_velocity(s.v[k], s.rotation[k], p.sx, p.sy);
    Kinematics<T> out;
    if (surface == Surface::Line) {
      out.normal = {T(nx), T(ny)};
      out.penetration = -(nx * (r.x - px) + ny * (r.y - py));
    } else {
      const Vec2<T> d{r.x - px, r.y - py};
      const T distance = sqrt(dot(d, d));
      const T sign = inside ? T(-1.0) : T(1.0);
      out.normal = {sign * d.x / distance, sign * d.y / distance};
      out.penetration = inside ? distance - radius : radius - distance;
    }
    out.tangent = {-out.normal.y, out.normal.x};
    out.rate = -dot(out.normal, v);
    out.slip = dot(out.tangent, v);
    return out;
  }

  /// Normal force of the contact mode, N(d, d') in segment `segment`.
  template <class T>
  T normal_force(const T& d, const T& rate, int segment) const {
    const T spring = segment == 0 ? stiffness * d : stiffness * breakpoint + stiffness_above * (d - breakpoint);
    return spring + damping * rate;
  }

  template <class T>
  void force_law(double /*t*/, const ElementState<T>& s, std::array<Pose<T>, 2>& f) const {
    const State& st = mode_as<State>(s);
    if (st.mode != Mode::Contact) return;
    const Kinematics<T> k = kinematics(s);
    const T normal = normal_force(k.penetration, k.rate, st.segment);
    const T tangential = friction > 0.0 ? -friction * normal * tanh(k.slip / friction_velocity) : T(0.0);
    const auto slot = static_cast<std::size_t>(point_slot(0));
    add_point_force(s.rotation[slot], point(0).sx, point(0).sy,
                    Vec2<T>{normal * k.normal.x + tangential * k.tangent.x, normal * k.normal.y + tangential * k.tangent.y},
                    f[slot]);
  }

  void initialize(const ElementState<double>& initial) override;
  int root_count() const override { return 3; }
  void roots_in(const State& st, const ElementState<double>& s, double* g) const;
  bool commit_in(State& st, int index, int direction, double t, const ElementState<double>& s, Event& event) const;
  /// In contact, on the stiffer of the two slopes.
  State stiffest_mode(const ElementState<double>& s) const;
  double potential_energy(const ElementState<double>& s) const override;
  /// The wall or barrier surface (none for wheel_rail: the animation draws the rail itself).
  std::optional<GroundSurface> ground_surface() const override;
  std::vector<std::string> output_names() const override { return {"normal_force", "friction_force", "penetration"}; }
  void outputs(const ElementState<double>& s, const double* lambda, double* out) const override;

 private:
  void enter_mode(State& st, double penetration, double rate) const;

  State initial_state_;  // the mode a run starts in (from the initial configuration)
  bool wheel_rail_;
};

}  // namespace railcrash
