// Hybrid force elements (design.md section 3): the adapter the piecewise force laws with modes
// derive from (contact, crush, anticlimber, beams, draft gear, coupler faces, coupling, the
// piecewise-linear springs), so that each writes its roots, commits and stiffest mode against its
// own State and none repeats the untyped slot handling.
#pragma once

#include <algorithm>
#include <array>

#include "railcrash/model/element.hpp"

namespace railcrash {

/// A position root on a history law's way back (an elastic line rejoining a curve, a gap
/// closing or opening): `distance` <= 0 once past the point, `rate` >= 0 moving across it. It is
/// crossed only while moving on; moving back it stays positive whatever the position, since the
/// constraints' position correction moves a deflection without its rate (a law resting on its
/// reversal point chattered between its two modes at one instant: bench/event_storms.py). At
/// rest (rate exactly 0: a static settle, a start at rest) the position alone decides.
inline double position_root_moving_on(double distance, double rate) {
  return rate == 0.0 ? distance : std::max(distance, -rate);
}

/// Adapter for a hybrid force element (design.md section 3: a piecewise law, smooth within each
/// mode, whose root functions say when to leave the mode). Derived writes its force law as for
/// ForceElement, declares its mode and history as a trivially copyable `State` (its slot, with
/// RAILCRASH_ELEMENT_MODE) and provides, on that State instead of the untyped slot:
///   void roots_in(const State& st, const ElementState<double>& s, double* g) const;
///       the root functions of mode st at s (Element::roots' convention)
///   bool commit_in(State& st, int index, int direction, double t, const ElementState<double>& s,
///                  Element::Event& event) const;
///       leaves mode st through root `index` (Element::commit's convention)
///   State stiffest_mode(const ElementState<double>& s) const;   (optional)
///       the mode of its stiffest law at s, whose force Jacobian sets explicit Euler's stability
///       limit (default: the current mode)
template <class Derived>
class HybridElement : public ForceElement<Derived> {
 public:
  using ForceElement<Derived>::ForceElement;

  void roots(double /*t*/, const ElementState<double>& s, const double* /*lambda*/, double* g) const override {
    derived().roots_in(mode_as<typename Derived::State>(s), s, g);
  }
  bool commit(int index, int direction, double t, const ElementState<double>& s, const double* /*lambda*/, void* mode,
              Element::Event& event) const override {
    return derived().commit_in(*static_cast<typename Derived::State*>(mode), index, direction, t, s, event);
  }
  void stiffest_force_jacobian(double t, const ElementState<double>& s, ForceBlock& df_dq,
                               ForceBlock& df_dv) const override {
    const auto stiffest = derived().stiffest_mode(s);
    std::array<Pose<double>, 2> f{};
    this->add_force_jacobian(t, in_mode(s, stiffest), f, df_dq, df_dv);
  }
  /// The default stiffest mode: the current one (Element::stiffest_force_jacobian's default).
  template <class E = Derived>
  typename E::State stiffest_mode(const ElementState<double>& s) const {
    return mode_as<typename E::State>(s);
  }

 private:
  const Derived& derived() const { return *static_cast<const Derived*>(this); }
};

}  // namespace railcrash
