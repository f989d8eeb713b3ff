// Energy absorbed per crush zone and per car (summary.json "crush_zones", energy_zones.csv, the
// report's bar chart and its loops over the declared curves).
//
// A crush zone is an element that absorbs energy by crushing: one with an output of the crush
// role, or with both a crash force and a crash deformation (a force-deformation loop): crush
// springs, anticlimbers and draft gears (element.hpp OutputRole). Per zone:
//   absorbed     the work done on the element so far, its work quadrature [energy]
//                (DaeSystem::kFirstElementWork + e): what it took out of the cars' motion
//   recoverable  its stored (elastic) energy now, what unloading would give back [energy]
//   dissipated   absorbed - (recoverable - recoverable at the start) [energy]: the energy
//                balance's share of the element (energy.csv's "dissipated.<type>" sums these)
//   peak_absorbed  the largest absorbed over the samples [energy]
//   capacity     the area under the declared loading curve from its first to its last point
//                [energy]: crush_spring its `curve`; anticlimber its horizontal bilinear law
//                up to horizontal_rupture_deflection (none without one: the curve has no
//                last point, it is drawn but has no capacity); draft_gear
//                initial_stiffness d + hysteresis_load up to `travel` (where it bottoms)
// A car's absorbed energy is the sum of its zones' (a zone between two cars counts half for
// each, as results.hpp's car crush counts it).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "railcrash/solver/dae_system.hpp"

namespace railcrash {

/// The loading curve an element declares and its unloading: (deformation [length], force
/// [force]) points in the units of the element's crash deformation and force outputs.
struct DeclaredCurve {
  std::vector<double> deformation, force;  // loading curve points, deformation increasing
  double unloading_stiffness = 0.0;        // [force/length] slope of the unloading line from the
                                           // largest deformation reached (0: none)
  std::vector<double> lower_deformation, lower_force;  // draft gear: the unloading curve it slides
                                                       // down to (empty: none)
  std::optional<double> beyond_last_slope;  // [force/length] the loading slope beyond the last point (draft
                                            // gear: after bottoming; none: the last segment's continues)
  bool open_ended = false;  // no last point (an anticlimber without a rupture deflection): no capacity
};

/// Area under the piecewise-linear curve from its first point to its last [force*length].
double area_under(const DeclaredCurve& curve);

/// The declared curve of a crush zone's element; none for an element without one.
std::optional<DeclaredCurve> declared_curve(const Element& element);

struct CrushZone {
  std::string element, type;
  int element_index = 0;
  std::vector<std::string> cars;  // the cars of its bodies (none: between bodies of no car)
  std::vector<double> shares;     // its share counted in each car (1 or 1/2)
  double absorbed = 0.0, peak_absorbed = 0.0, recoverable = 0.0, dissipated = 0.0;  // [energy]
  double initial_recoverable = 0.0;                                                  // [energy]
  std::optional<DeclaredCurve> curve;
  std::optional<double> capacity;  // [energy] area under the declared curve
};

struct CarEnergy {
  std::string car;
  double absorbed = 0.0;  // [energy] sum of share x absorbed of its zones
  double capacity = 0.0;  // [energy] the same sum of the capacities (zones without one count 0)
};

/// The crush zones of a system and their absorbed energies over a run.
class CrushZoneTracker {
 public:
  explicit CrushZoneTracker(const DaeSystem& system);
  /// An output sample: state y and quadratures (null: no work known yet).
  void sample(const double* y, const double* quadratures);
  const std::vector<CrushZone>& zones() const { return zones_; }
  std::vector<CarEnergy> cars() const;
  double total_absorbed() const;
  /// summary.json's "crush_zones" value (an object).
  std::string json(bool si) const;
  /// energy_zones.csv's text after its provenance line: one row per zone, per car and the total.
  std::string csv() const;

 private:
  const DaeSystem& system_;
  std::vector<CrushZone> zones_;
  std::vector<std::string> car_order_;
  bool first_ = true;
};

}  // namespace railcrash
