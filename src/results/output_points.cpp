// Motion of the model's output points (see the header).
#include "railcrash/results/output_points.hpp"

#include <cmath>

namespace railcrash {

std::vector<std::string> output_point_columns(const std::vector<OutputPoint>& output_points) {
  std::vector<std::string> columns;
  for (const OutputPoint& o : output_points) {
    if (o.position) columns.insert(columns.end(), {o.name + ".x", o.name + ".y"});
    if (o.velocity) columns.insert(columns.end(), {o.name + ".vx", o.name + ".vy"});
    if (o.acceleration) columns.insert(columns.end(), {o.name + ".ax", o.name + ".ay"});
  }
  return columns;
}

void output_point_values(const std::vector<OutputPoint>& output_points, const double* q, const double* v, const double* acceleration,
                         std::vector<double>& out) {
  out.clear();
  for (const OutputPoint& o : output_points) {
    const int b = o.point.body;
    const double theta = q[3 * b + 2], omega = v[3 * b + 2], alpha = acceleration[3 * b + 2];
    const double c = std::cos(theta), s = std::sin(theta);
    const double rx = c * o.point.sx - s * o.point.sy, ry = s * o.point.sx + c * o.point.sy;  // R(theta) s [length]
    if (o.position) out.insert(out.end(), {q[3 * b] + rx, q[3 * b + 1] + ry});
    if (o.velocity) out.insert(out.end(), {v[3 * b] - omega * ry, v[3 * b + 1] + omega * rx});
    if (o.acceleration)
      out.insert(out.end(), {acceleration[3 * b] - alpha * ry - omega * omega * rx, acceleration[3 * b + 1] + alpha * rx - omega * omega * ry});
  }
}

}  // namespace railcrash
