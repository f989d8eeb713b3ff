#pragma once
// Accuracy warnings: a finished run whose own energy balance or constraint residual says that
// its numbers carry an integration error larger than an engineer would hand in.
//
// Two measures every run already reports (summary.json's energy and constraint_residual_max):
//   - the energy the integration created or lost, as a share of the energy turned over:
//       share = |integration_drift| / max(|initial total|, |kinetic| + |elastic| + |gravity|
//                                                          + |dissipated| + |external work|)
//     (summary.json's relative_balance_error);
//   - the largest constraint residual |Phi| at the output samples, a length (an angle row
//     counts at its bodies' size, DaeSystem::constraint_row_length): with Euler it is how far
//     its penalty springs let the joints open.
// A run is warned about when the share exceeds kEnergyShareLimit or the residual exceeds
// kConstraintResidualLimit, and (a setting, not a measure) when IDA held its positions to the
// relative tolerance on a model farther from its origin than kOriginDistanceLimit times its size. The limits are stated, not tuned to pass: on the report's models
// (in-lbf-s) Euler at the printed step turns 0.015-0.087 % and opens joints by at most
// 0.015 mm; on the SI example models its default step creates 2.9-9.9 % and opens joints by
// 6 to 68 mm (bench/accuracy_warnings.py prints these figures; README "Accuracy warnings").
#include <string>
#include <vector>

#include "railcrash/model/model.hpp"

namespace railcrash {

struct EnergyBalance;
struct RunOutcome;

constexpr double kEnergyShareLimit = 0.01;          // [-] of the energy turned over
constexpr double kConstraintResidualLimit = 1.0e-3;  // [m] (converted to the model's length unit)
// IDA's relative position tolerance, rtol |q| + atol (atol 0.1 rtol L), grows with the
// distance of the model from its origin: past this many times its own size, the run says so.
// mu_3plus3_si (120 m) at its own rtol 1e-5 moved 10 km along x (84 sizes) ends its largest
// crush 9.1e-4 short of the rtol 1e-9 run, 100 km along (838 sizes) 1.3e-3, at the origin
// 3.7e-4 and 1 km along (8.9 sizes) 4.3e-4; the absolute form 0.9-1.1e-4 at every distance
// (bench/position_origin.py).
constexpr double kOriginDistanceLimit = 10.0;  // [model sizes]

/// summary.json's relative_balance_error: the energy the integration gained (error()) over the
/// energy turned over, at the end or the most at any output sample (most_turned_over,
/// RunOutcome::most_energy_turned_over), whichever is larger; 0 for a model that turns none over.
/// With the end alone, a pendulum from rest that ended at its turning point read "created
/// 100 %" for a drift of 7e-7 J.
double relative_balance_error(const EnergyBalance& energy, double most_turned_over);

/// What the run said about its own accuracy, as what an engineer would act on.
struct AccuracyFacts {
  double relative_balance_error = 0.0;    // [-] as summary.json
  double max_constraint_residual = 0.0;   // [length of the model's unit system]
  UnitSystem units = UnitSystem::SI;
  bool euler_ran = false;                 // Euler integrated all of the run or a part (auto's hand-over)
  double euler_step = 0.0;                // [s] its step, when euler_ran
  double ida_took_back_at = -1.0;         // [s] auto: IDA took the run back from Euler then (-1: it did not)
  double euler_from = -1.0;               // [s] auto: Euler's part began then (-1: Euler ran all the run)
  double origin_distance_in_sizes = 0.0;  // [-] IDA's relative position tolerance: RunStatistics' figure
};

/// The facts of a finished run; `integrator` is the method the run was set to ("ida", "euler"
/// or "auto": auto counts as Euler from its hand-over on).
AccuracyFacts accuracy_facts(const RunOutcome& outcome, const std::string& integrator, UnitSystem units);

/// One sentence per limit exceeded, each naming the figure, the limit and what to change; empty
/// when the run is within both limits.
std::vector<std::string> accuracy_warnings(const AccuracyFacts& facts);

}  // namespace railcrash
