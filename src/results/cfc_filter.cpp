// CFC filters of SAE J211-1 Appendix C / ISO 6487 (see the header for the formulas).
#include "railcrash/results/cfc_filter.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace railcrash::cfc {

namespace {

constexpr double kPi = 3.14159265358979323846;

/// One forward pass of the second-order section over x, started at rest on x[0] (the
/// extension in front makes the start-up transient die out before the record begins).
void forward_pass(const Coefficients& c, std::vector<double>& x) {
  if (x.empty()) return;
  double x1 = x[0], x2 = x[0], y1 = x[0], y2 = x[0];  // steady state on the first value (DC gain 1)
  for (double& value : x) {
    const double y = c.a0 * value + c.a1 * x1 + c.a2 * x2 + c.b1 * y1 + c.b2 * y2;
    x2 = x1;
    x1 = value;
    y2 = y1;
    y1 = y;
    value = y;
  }
}

}  // namespace

double design_frequency(double cfc) { return 2.0775 * cfc; }

double end_zone(double cfc) { return std::sqrt(2.0) * std::log(100.0) / (2.0 * kPi * design_frequency(cfc)); }

Coefficients coefficients(double cfc, double interval) {
  if (!(cfc > 0.0) || !std::isfinite(cfc)) throw std::invalid_argument("CFC class must be a positive number");
  if (!(interval > 0.0) || !std::isfinite(interval)) throw std::invalid_argument("sample interval must be positive");
  const double half_angle = kPi * design_frequency(cfc) * interval;  // wd T / 2
  if (half_angle >= 0.5 * kPi)
    throw std::invalid_argument("sample interval " + std::to_string(interval) + " s is too long for CFC " +
                                std::to_string(cfc) + ": it must be below " + std::to_string(0.5 / design_frequency(cfc)) + " s");
  const double wa = std::sin(half_angle) / std::cos(half_angle);
  const double root2 = std::sqrt(2.0);
  const double denominator = 1.0 + root2 * wa + wa * wa;
  Coefficients c;
  c.a0 = wa * wa / denominator;
  c.a1 = 2.0 * c.a0;
  c.a2 = c.a0;
  c.b1 = -2.0 * (wa * wa - 1.0) / denominator;
  c.b2 = (-1.0 + root2 * wa - wa * wa) / denominator;
  return c;
}

bool adequately_sampled(double cfc, double interval) { return interval > 0.0 && 1.0 / interval >= 10.0 * cfc * (1.0 - 1e-9); }

std::vector<double> filter(const std::vector<double>& samples, double interval, double cfc) {
  const Coefficients c = coefficients(cfc, interval);
  const std::size_t n = samples.size();
  if (n < 2) return samples;
  const double memory = 4.0 / (design_frequency(cfc) * interval);  // samples
  const std::size_t pad = std::min(n - 1, static_cast<std::size_t>(std::ceil(memory)));
  std::vector<double> x;
  x.reserve(n + 2 * pad);
  for (std::size_t k = pad; k >= 1; --k) x.push_back(2.0 * samples.front() - samples[k]);
  x.insert(x.end(), samples.begin(), samples.end());
  for (std::size_t k = 1; k <= pad; ++k) x.push_back(2.0 * samples.back() - samples[n - 1 - k]);
  forward_pass(c, x);
  std::reverse(x.begin(), x.end());
  forward_pass(c, x);
  std::reverse(x.begin(), x.end());
  return std::vector<double>(x.begin() + static_cast<std::ptrdiff_t>(pad), x.begin() + static_cast<std::ptrdiff_t>(pad + n));
}

double two_pass_gain(double cfc, double interval, double frequency) {
  const double ratio = std::tan(kPi * frequency * interval) / std::tan(kPi * design_frequency(cfc) * interval);
  return 1.0 / (1.0 + std::pow(ratio, 4));
}

CorridorLimits corridor(double cfc, double frequency) {
  // J211-1 Table 1: FH = CFC; FN = 100, 300, 1000, 1650 Hz for CFC 60, 180, 600, 1000. Lines:
  // a (+-0.5 dB, FL to FH), b (+0.5 / -1 dB at FH), c (+0.5 / -4 dB at FN), d (-9 dB/octave
  // above FN, upper limit). Between FH and FN the lower limit is taken linear in log f from -1
  // to -4 dB. The steeper lines e (-24 dB/octave) and g (-30 dB) are not modelled here.
  const double fh = cfc, fn = cfc == 1000.0 ? 1650.0 : cfc * 5.0 / 3.0;
  const double inf = std::numeric_limits<double>::infinity();
  if (frequency < fh) return {-0.5, 0.5};
  if (frequency <= fn) {
    const double s = std::log(frequency / fh) / std::log(fn / fh);
    return {-1.0 - 3.0 * s, 0.5};
  }
  return {-inf, 0.5 - 9.0 * std::log2(frequency / fn)};
}

std::vector<double> resample_uniform(const std::vector<double>& times, const std::vector<double>& values, double interval) {
  std::vector<double> out;
  if (times.empty() || times.size() != values.size() || !(interval > 0.0)) return out;
  const double t0 = times.front(), t1 = times.back();
  const std::size_t count = static_cast<std::size_t>(std::floor((t1 - t0) / interval * (1.0 + 1e-12))) + 1;
  out.reserve(count);
  std::size_t k = 0;
  for (std::size_t i = 0; i < count; ++i) {
    const double t = t0 + static_cast<double>(i) * interval;
    while (k + 1 < times.size() && times[k + 1] < t) ++k;
    if (k + 1 >= times.size()) {
      out.push_back(values.back());
      continue;
    }
    const double span = times[k + 1] - times[k];
    const double s = span > 0.0 ? std::clamp((t - times[k]) / span, 0.0, 1.0) : 1.0;
    out.push_back(values[k] + s * (values[k + 1] - values[k]));
  }
  return out;
}

double typical_interval(const std::vector<double>& times) {
  if (times.size() < 2) return 0.0;
  std::vector<double> steps;
  steps.reserve(times.size() - 1);
  for (std::size_t k = 1; k < times.size(); ++k) steps.push_back(times[k] - times[k - 1]);
  std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2), steps.end());
  return steps[steps.size() / 2];
}

}  // namespace railcrash::cfc
