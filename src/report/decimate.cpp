// Min/max-preserving decimation (see the header).
#include "railcrash/report/decimate.hpp"

#include <algorithm>

namespace railcrash::report {

Decimated decimate_minmax(const std::vector<double>& x, const std::vector<std::vector<double>>& series, std::size_t max_points) {
  Decimated out;
  const std::size_t n = x.size();
  max_points = std::max<std::size_t>(max_points, 2);
  if (n <= max_points) {
    out.x = x;
    out.series = series;
    return out;
  }
  const std::size_t buckets = max_points / 2;
  out.series.assign(series.size(), {});
  for (std::size_t b = 0; b < buckets; ++b) {
    const std::size_t begin = b * n / buckets, end = (b + 1) * n / buckets;  // [begin, end)
    out.x.push_back(x[begin]);
    out.x.push_back(x[end - 1]);
    for (std::size_t s = 0; s < series.size(); ++s) {
      const std::vector<double>& v = series[s];
      const auto range_begin = v.begin() + static_cast<std::ptrdiff_t>(begin), range_end = v.begin() + static_cast<std::ptrdiff_t>(end);
      const auto [low, high] = std::minmax_element(range_begin, range_end);
      const bool low_first = low <= high;
      out.series[s].push_back(low_first ? *low : *high);
      out.series[s].push_back(low_first ? *high : *low);
    }
  }
  return out;
}

std::vector<std::size_t> decimate_path(const std::vector<double>& a, const std::vector<double>& b, std::size_t max_points) {
  const std::size_t n = std::min(a.size(), b.size());
  std::vector<std::size_t> keep;
  if (n <= std::max<std::size_t>(max_points, 8)) {
    for (std::size_t k = 0; k < n; ++k) keep.push_back(k);
    return keep;
  }
  const std::size_t buckets = std::max<std::size_t>(max_points, 8) / 5;
  for (std::size_t bucket = 0; bucket < buckets; ++bucket) {
    const std::size_t begin = bucket * n / buckets, end = (bucket + 1) * n / buckets;
    std::vector<std::size_t> chosen{begin};
    const auto pick = [&](const std::vector<double>& v) {
      const auto range = std::minmax_element(v.begin() + static_cast<std::ptrdiff_t>(begin), v.begin() + static_cast<std::ptrdiff_t>(end));
      chosen.push_back(static_cast<std::size_t>(range.first - v.begin()));
      chosen.push_back(static_cast<std::size_t>(range.second - v.begin()));
    };
    pick(a);
    pick(b);
    std::sort(chosen.begin(), chosen.end());
    chosen.erase(std::unique(chosen.begin(), chosen.end()), chosen.end());
    keep.insert(keep.end(), chosen.begin(), chosen.end());
  }
  if (keep.back() != n - 1) keep.push_back(n - 1);
  return keep;
}

}  // namespace railcrash::report
