// The run's output points (`outputs:`, model/run_spec.hpp) in timeseries.csv: the position, velocity
// and acceleration of a point fixed on a body, from the body's state and its accelerations
// (results.hpp: v' from the equations of motion with IDA's multipliers, or with the penalty
// forces of the step Euler just took):
//   r = r_cm + R(theta) s
//   v = v_cm + omega x (R s)                  = v_cm + omega (-(R s)_y, (R s)_x)
//   a = a_cm + alpha x (R s) - omega^2 (R s)
#pragma once

#include <string>
#include <vector>

#include "railcrash/model/run_spec.hpp"

namespace railcrash {

/// Column names of the output points, in their order: <name>.x,<name>.y, .vx,.vy, .ax,.ay as asked.
std::vector<std::string> output_point_columns(const std::vector<OutputPoint>& output_points);

/// Their values at a state: q and v (3 per body: x, y, theta and their rates), acceleration
/// (3 per body). `out` is resized to the number of columns.
void output_point_values(const std::vector<OutputPoint>& output_points, const double* q, const double* v, const double* acceleration,
                         std::vector<double>& out);

}  // namespace railcrash
