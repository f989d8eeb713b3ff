// Decimation of long time series for plotting that never drops a peak.
//
// decimate_minmax: the samples are split into buckets of equal count; each bucket becomes two
// points, at the times of its first and last sample, and every series takes there its
// minimum and maximum over the bucket, in the order they occur. Every local extreme value is
// kept exactly; its time moves by at most one bucket (max_points / 2 buckets over the record).
// decimate_path: for x-y curves (force-deformation loops) the indices to keep: per bucket the
// first sample and the samples of the smallest and largest x and y, in order.
#pragma once

#include <cstddef>
#include <vector>

namespace railcrash::report {

struct Decimated {
  std::vector<double> x;
  std::vector<std::vector<double>> series;
};

/// At most max_points (>= 2) points per series; unchanged when there are no more samples than that.
Decimated decimate_minmax(const std::vector<double>& x, const std::vector<std::vector<double>>& series, std::size_t max_points);

/// Indices (increasing) of at most max_points (>= 8) samples of the curve (a[k], b[k]).
std::vector<std::size_t> decimate_path(const std::vector<double>& a, const std::vector<double>& b, std::size_t max_points);

}  // namespace railcrash::report
