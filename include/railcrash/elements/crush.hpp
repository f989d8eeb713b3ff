// Crushable structure: crush_spring (not in the 1980 report; the force-crush
// characteristic every modern lumped-mass crash model uses, e.g. the lead car's front end
// in the two-car barrier test).
//
// Between points P1 (body 1) and P2 (body 2), length L = |r2 - r1|, u = (r2 - r1) / L:
//   crush          d = free_length - L          (positive when shortened)
//   crush force    P >= 0 pushes the points apart: force on P2 = +P u, on P1 = -P u
// Modes (history: largest crush d_max, permanent crush d_p; changed only at events):
//   loading, segment k   P = F_k + (F_k+1 - F_k)(d - d_k)/(d_k+1 - d_k) on the `curve`
//                         [[d_0, F_0], [d_1, F_1], ...] (beyond the last point, the last
//                         segment's slope continues)
//                         leaves when d' < 0 (unloading), d < d_k or d > d_k+1 (next segment)
//   elastic               P = unloading_stiffness (d - d_p), below the curve; on leaving
//                         the curve d_p = d_max - F(d_max) / unloading_stiffness
//                         leaves when d > d_max (back on the curve) or d < d_p (force zero)
//   open                  P = 0, or tension_stiffness * (d - d_p) (< 0) when that is given
//                         leaves when d > d_p (contact again: elastic, or loading if the
//                         structure has never been crushed)
// In every mode, L reaching 1e-3 free_length (the points meet), or the points passing each
// other (PointsMeet, springs.hpp), stops the run with a message: the force has no direction
// there (a curve may be tabulated beyond free_length; that part is never reached).
// Roots are written positive inside their mode (element.hpp's convention).
// The loader refuses an unloading_stiffness below the curve's steepest segment slope: from a
// crush on such a segment the unloading line would rise above the loading curve (more force
// unloading than crushing, more energy stored than the work done). Equal to it (within 1e-9 of
// it, for unit conversions' round-off) is accepted. A model that sets unloading_above_curve:
// true is accepted all the same: it says so where the element is written (energy.csv then
// shows the crush springs' negative dissipation while they unload from those segments).
// Elastic energy is P^2 / (2 unloading_stiffness) (what unloading would give back); the
// rest of the work done on the element is dissipated in crushing.
#pragma once

#include <optional>
#include <vector>

#include "railcrash/elements/hybrid.hpp"
#include "railcrash/elements/springs.hpp"
#include "railcrash/model/element.hpp"
#include "railcrash/model/element_registry.hpp"

namespace railcrash {

class CrushSpring : public HybridElement<CrushSpring> {
 public:
  explicit CrushSpring(ElementSpec& spec);

  std::vector<double> curve_crush;      // [length] d_k, increasing, d_0 >= 0
  std::vector<double> curve_force;      // [force] F_k >= 0
  double unloading_stiffness;           // [force/length]
  std::optional<double> tension_stiffness;  // [force/length]; none: no tension
  std::optional<double> free_length;    // [length]; default: initial length
  bool unloading_above_curve = false;   // accept unloading_stiffness below the steepest slope (see above)

  enum class Mode { Loading, Elastic, Open };
  struct State {
    Mode mode = Mode::Open;
    int segment = 0;        // loading: curve segment k (d_k .. d_k+1)
    double max_crush = 0.0; // [length] d_max
    double permanent_crush = 0.0;  // [length] d_p
    bool crushed = false;   // has ever been on the curve
  };
  RAILCRASH_ELEMENT_MODE(State, initial_state_)

  template <class T>
  void force_law(double /*t*/, const ElementState<T>& s, std::array<Pose<T>, 2>& f) const {
    line_force_law(s, mode_as<State>(s), unloading_stiffness, f);
  }

  /// Crush force P(d) in mode st.
  template <class T>
  T crush_force(const State& st, const T& crush) const {
    return crush_force(st, crush, unloading_stiffness);
  }

  /// Force on the loading curve at crush d (extrapolated with the last slope).
  double curve_at(double crush) const;
  double segment_slope(int segment) const;

  void initialize(const ElementState<double>& initial) override;
  /// Root 3, in every mode: P2 comes within PointsMeet::kFraction of the free length of P1, or
  /// passes it (PointsMeet, springs.hpp) (crush reaches 99.9 % of free_length). The run stops
  /// there with a message naming the element (SolverError from commit): beyond it
  /// u = (r2 - r1) / L is lost, and Euler went on through the other side with the force
  /// reversed (a silent wrong answer).
  static constexpr int kPointsMeetRoot = 3;
  int root_count() const override { return 4; }
  /// Root 3's value (PointsMeet::gap) [length].
  double points_meet_gap(const ElementState<double>& s) const { return points_meet_.gap(*this, s, *free_length); }
  void roots_in(const State& st, const ElementState<double>& s, double* g) const;
  bool commit_in(State& st, int index, int direction, double t, const ElementState<double>& s, Event& event) const;
  void stiffest_force_jacobian(double t, const ElementState<double>& s, ForceBlock& df_dq, ForceBlock& df_dv) const override;
  double potential_energy(const ElementState<double>& s) const override;
  std::vector<std::string> output_names() const override { return {"force", "crush", "permanent_crush"}; }
  std::vector<RoleOfOutput> output_roles() const override {
    return {{OutputRole::Crush, "crush"}, {OutputRole::CrashForce, "force"}, {OutputRole::CrashDeformation, "crush"}};
  }
  void outputs(const ElementState<double>& s, const double* lambda, double* out) const override;

 private:
  /// The law with the elastic (unloading) stiffness given: force on P2 = +P u = P d / L.
  template <class T>
  void line_force_law(const ElementState<T>& s, const State& st, double elastic_stiffness, std::array<Pose<T>, 2>& f) const {
    const LineGeometry<T> g = line_geometry(*this, s);
    const T crush = *free_length - g.length;
    const T force = crush_force(st, crush, elastic_stiffness);
    const T scale = force / g.length;
    apply_line_force(*this, s, Vec2<T>{scale * g.d.x, scale * g.d.y}, f);
  }
  template <class T>
  T crush_force(const State& st, const T& crush, double elastic_stiffness) const {
    switch (st.mode) {
      case Mode::Loading: {
        const auto k = static_cast<std::size_t>(st.segment);
        return curve_force[k] + segment_slope(st.segment) * (crush - curve_crush[k]);
      }
      case Mode::Elastic:
        return elastic_stiffness * (crush - st.permanent_crush);
      case Mode::Open:
        break;
    }
    if (tension_stiffness) return *tension_stiffness * (crush - st.permanent_crush);
    return T(0.0);
  }
  /// Mode for a state at crush d with crush rate rate, given the history in st.
  void enter_mode_at(State& st, double crush, double rate) const;
  double crush_of(const ElementState<double>& s) const;
  double crush_rate_of(const ElementState<double>& s) const;

  State initial_state_;  // the mode a run starts in (from the initial configuration)
  PointsMeet points_meet_;
};

}  // namespace railcrash
