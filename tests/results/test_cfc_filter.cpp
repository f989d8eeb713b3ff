// CFC filters (SAE J211-1 / ISO 6487) against the standard's corridor, the exact response
// of the two-pass Butterworth filter, and analytic inputs; the crash pulse's mean deceleration.
#include <catch2/catch.hpp>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "railcrash/results/cfc_filter.hpp"
#include "railcrash/results/crash_pulse.hpp"

namespace {

constexpr double kPi = 3.14159265358979323846;

std::vector<double> sine(double frequency, double interval, std::size_t count) {
  std::vector<double> x(count);
  for (std::size_t k = 0; k < count; ++k) x[k] = std::sin(2.0 * kPi * frequency * static_cast<double>(k) * interval);
  return x;
}

/// Amplitude of the middle half of a filtered sine: least-squares fit of sin and cos at f.
double measured_gain(double cfc, double interval, double frequency) {
  const std::size_t count = 40000;
  const std::vector<double> y = railcrash::cfc::filter(sine(frequency, interval, count), interval, cfc);
  double ss = 0, sc = 0, cc = 0, ys = 0, yc = 0;
  for (std::size_t k = count / 4; k < 3 * count / 4; ++k) {
    const double phase = 2.0 * kPi * frequency * static_cast<double>(k) * interval;
    const double s = std::sin(phase), c = std::cos(phase);
    ss += s * s; sc += s * c; cc += c * c; ys += y[k] * s; yc += y[k] * c;
  }
  const double det = ss * cc - sc * sc;
  const double a = (ys * cc - yc * sc) / det, b = (yc * ss - ys * sc) / det;
  return std::hypot(a, b);
}

}  // namespace

TEST_CASE("CFC coefficients follow SAE J211-1 Appendix C", "[cfc]") {
  using namespace railcrash::cfc;
  // CFC 60 at 10 kHz, computed by hand from the Appendix C formulas:
  // wd = 2 pi 60 2.0775 = 783.20 rad/s, wa = tan(wd T / 2) = tan(0.03915995) = 0.0391800 (x + x^3 / 3)
  const Coefficients c = coefficients(60.0, 1e-4);
  const double wa = std::tan(kPi * 60.0 * 2.0775 * 1e-4);
  CHECK(wa == Approx(0.0391800).epsilon(1e-5));
  const double d = 1.0 + std::sqrt(2.0) * wa + wa * wa;
  CHECK(c.a0 == Approx(wa * wa / d).epsilon(1e-12));
  CHECK(c.a1 == Approx(2.0 * c.a0));
  CHECK(c.a2 == Approx(c.a0));
  CHECK(c.b1 == Approx(-2.0 * (wa * wa - 1.0) / d).epsilon(1e-12));
  CHECK(c.b2 == Approx((-1.0 + std::sqrt(2.0) * wa - wa * wa) / d).epsilon(1e-12));
  // DC gain of one pass is 1: (a0 + a1 + a2) / (1 - b1 - b2).
  CHECK((c.a0 + c.a1 + c.a2) / (1.0 - c.b1 - c.b2) == Approx(1.0).epsilon(1e-12));
  CHECK_THROWS_AS(coefficients(60.0, 0.005), std::invalid_argument);  // fd T = 0.62 > 1/2
  CHECK_THROWS_AS(coefficients(0.0, 1e-4), std::invalid_argument);
  CHECK(adequately_sampled(60.0, 1.0 / 600.0));
  CHECK_FALSE(adequately_sampled(60.0, 1.0 / 500.0));
}

TEST_CASE("CFC filters' frequency response lies in the J211 corridor and equals the two-pass Butterworth's", "[cfc]") {
  using namespace railcrash::cfc;
  for (const double cfc : {60.0, 180.0, 600.0, 1000.0}) {
    const double interval = 1.0 / (100.0 * cfc);  // sampled at 100 CFC, as test data often is
    const double f3 = 5.0 / 3.0 * cfc;
    CHECK(20.0 * std::log10(two_pass_gain(cfc, interval, f3)) == Approx(-3.0).margin(0.1));  // -3 dB at FN
    for (const double ratio : {0.05, 0.2, 0.5, 0.8, 1.0, 1.3, 5.0 / 3.0, 2.0, 3.0, 5.0}) {
      const double f = ratio * cfc;
      const double gain = measured_gain(cfc, interval, f);
      INFO("CFC " << cfc << " at " << f << " Hz: gain " << gain);
      CHECK(gain == Approx(two_pass_gain(cfc, interval, f)).margin(2e-4));
      const double db = 20.0 * std::log10(gain);
      const CorridorLimits limits = corridor(cfc, f);
      CHECK(db <= limits.upper_db);
      CHECK(db >= limits.lower_db);
    }
  }
  // CFC 60 at 100 Hz is -3 dB (the standard's FN), at 60 Hz -20 log10(1 + (60 / 124.65)^4) = -0.454 dB.
  CHECK(20.0 * std::log10(measured_gain(60.0, 1e-4, 100.0)) == Approx(-3.01).margin(0.05));
  CHECK(20.0 * std::log10(measured_gain(60.0, 1e-4, 60.0)) == Approx(-0.454).margin(0.01));
}

TEST_CASE("CFC filter on analytic inputs: constant, ramp, slow and short half-sine pulses", "[cfc]") {
  using namespace railcrash::cfc;
  const double interval = 1e-4;  // [s]
  std::vector<double> constant(3000, 9.81), ramp(3000);
  for (std::size_t k = 0; k < ramp.size(); ++k) ramp[k] = 2.0 + 50.0 * static_cast<double>(k) * interval;
  const std::vector<double> c = filter(constant, interval, 60.0), r = filter(ramp, interval, 60.0);
  for (std::size_t k = 0; k < c.size(); ++k) {
    CHECK(c[k] == Approx(9.81).epsilon(1e-12));
    CHECK(r[k] == Approx(ramp[k]).epsilon(1e-9));  // the end reflection keeps a line a line
  }
  // A 100 ms half-sine of 10 g (all its energy below 10 Hz) passes CFC 60 within 0.5 %; a
  // 2 ms half-sine (energy up to about 500 Hz) loses most of its peak.
  const auto half_sine = [&](double duration) {
    std::vector<double> x(static_cast<std::size_t>(0.4 / interval), 0.0);
    for (std::size_t k = 0; k < x.size(); ++k) {
      const double t = static_cast<double>(k) * interval - 0.1;
      if (t > 0.0 && t < duration) x[k] = 10.0 * std::sin(kPi * t / duration);
    }
    return x;
  };
  const auto peak = [](const std::vector<double>& x) {
    double p = 0.0;
    for (double v : x) p = std::max(p, std::abs(v));
    return p;
  };
  CHECK(peak(filter(half_sine(0.1), interval, 60.0)) == Approx(10.0).epsilon(5e-3));
  const double short_peak = peak(filter(half_sine(0.002), interval, 60.0));
  CHECK(short_peak < 4.0);
  CHECK(short_peak > 1.0);
  // The area of the pulse (its velocity change) is kept: DC gain 1, no phase.
  const std::vector<double> pulse = half_sine(0.002), filtered = filter(pulse, interval, 60.0);
  double area = 0.0, filtered_area = 0.0;
  for (std::size_t k = 0; k < pulse.size(); ++k) { area += pulse[k]; filtered_area += filtered[k]; }
  CHECK(filtered_area == Approx(area).epsilon(1e-6));
}

TEST_CASE("CFC filter's end zone: a last-sample spike comes through whole, and is gone before the zone", "[cfc]") {
  using namespace railcrash::cfc;
  // end_zone = sqrt(2) ln(100) / (2 pi fd): 8.3155 ms at CFC 60, a third of that at CFC 180.
  CHECK(end_zone(60.0) == Approx(std::sqrt(2.0) * std::log(100.0) / (2.0 * kPi * 2.0775 * 60.0)).epsilon(1e-15));
  CHECK(end_zone(60.0) == Approx(8.3155e-3).epsilon(1e-4));
  CHECK(end_zone(180.0) == Approx(end_zone(60.0) / 3.0).epsilon(1e-12));
  for (const double interval : {1e-3, 5e-4, 1e-4, 1e-5}) {
    // Zeros, then one sample of 1 at the record's end (a light body ringing at the last row):
    // the point reflection extends it as a step of 2, and the filtered end is the spike.
    std::vector<double> x(static_cast<std::size_t>(0.2 / interval), 0.0);
    x.back() = 1.0;
    const std::vector<double> y = filter(x, interval, 60.0);
    INFO("interval " << interval);
    CHECK(y.back() == Approx(1.0).epsilon(1e-9));
    double before_zone = 0.0, in_last_quarter = 0.0;
    for (std::size_t k = 0; k < y.size(); ++k) {
      const double time_to_end = static_cast<double>(y.size() - 1 - k) * interval;
      if (time_to_end > end_zone(60.0)) before_zone = std::max(before_zone, std::abs(y[k]));
      if (time_to_end > 0.0 && time_to_end <= 0.25 * end_zone(60.0)) in_last_quarter = std::max(in_last_quarter, std::abs(y[k]));
    }
    CHECK(before_zone < 5e-3);  // under 0.5 % of the spike: the zone is long enough
    if (interval < 1e-3) CHECK(in_last_quarter > 0.2);  // and not needlessly long
  }
}

TEST_CASE("Uniform resampling and the typical interval", "[cfc]") {
  using namespace railcrash::cfc;
  const std::vector<double> t{0.0, 0.001, 0.002, 0.003, 0.0035}, v{0.0, 1.0, 2.0, 3.0, 3.5};
  CHECK(typical_interval(t) == Approx(0.001));
  const std::vector<double> u = resample_uniform(t, v, 0.0005);
  REQUIRE(u.size() == 8);
  for (std::size_t k = 0; k < u.size(); ++k) CHECK(u[k] == Approx(0.5 * static_cast<double>(k)));
}

TEST_CASE("Mean deceleration over the collision: constant and half-sine pulses", "[cfc]") {
  const double interval = 1e-4;
  std::vector<double> t, constant, half_sine;
  for (int k = 0; k <= 5000; ++k) {
    const double time = k * interval;
    t.push_back(time);
    // 20 m/s, 5 g from 0.1 s to 0.2 s, then constant.
    const double tc = std::clamp(time - 0.1, 0.0, 0.1);
    constant.push_back(20.0 - 49.0 * tc);
    // Half-sine of amplitude 100 m/s^2 over 80 ms from 0.05 s: dv = 2 A tau / pi.
    const double ts = std::clamp(time - 0.05, 0.0, 0.08);
    half_sine.push_back(10.0 - 100.0 * 0.08 / kPi * (1.0 - std::cos(kPi * ts / 0.08)));
  }
  const railcrash::CollisionPulse a = railcrash::collision_pulse(t, constant);
  REQUIRE(a.found);
  CHECK(a.complete);
  CHECK(a.t_start == Approx(0.1).margin(1.5e-4));
  CHECK(a.t_end == Approx(0.2).margin(1.5e-4));
  CHECK(a.mean_deceleration == Approx(49.0).epsilon(1e-3));
  CHECK(a.velocity_change == Approx(-4.9).margin(0.01));
  const railcrash::CollisionPulse b = railcrash::collision_pulse(t, half_sine);
  CHECK(b.complete);
  CHECK(b.mean_deceleration == Approx(2.0 * 100.0 / kPi).epsilon(1e-2));  // mean of a half-sine; the start sample is 0.6 % late
  // A run that stops mid-collision: not complete, mean over what there is.
  const std::vector<double> t_short(t.begin(), t.begin() + 1500), v_short(constant.begin(), constant.begin() + 1500);
  const railcrash::CollisionPulse c = railcrash::collision_pulse(t_short, v_short);
  CHECK_FALSE(c.complete);
  CHECK(c.mean_deceleration == Approx(49.0).epsilon(1e-3));
  CHECK_FALSE(railcrash::collision_pulse(t, std::vector<double>(t.size(), 3.0)).found);
}
