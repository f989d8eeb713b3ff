// Channel-frequency-class (CFC) filters of SAE J211-1 (Instrumentation for Impact Test, Part 1,
// Appendix C) and ISO 6487 (Road vehicles - Measurement techniques in impact tests): a
// second-order Butterworth low-pass run forward and then backward over the samples, so that
// the result has no phase shift and the magnitude response of a fourth-order filter.
//
// Coefficients (J211-1 Appendix C; T = sample interval [s], CFC = 60, 180, 600 or 1000):
//   wd = 2 pi CFC 2.0775                     design frequency [rad/s]
//   wa = sin(wd T / 2) / cos(wd T / 2)       prewarped
//   a0 = wa^2 / (1 + sqrt(2) wa + wa^2),  a1 = 2 a0,  a2 = a0
//   b1 = -2 (wa^2 - 1) / (1 + sqrt(2) wa + wa^2)
//   b2 = (-1 + sqrt(2) wa - wa^2) / (1 + sqrt(2) wa + wa^2)
//   Y[t] = a0 X[t] + a1 X[t-1] + a2 X[t-2] + b1 Y[t-1] + b2 Y[t-2]
// A single pass is the bilinear transform of the analogue Butterworth filter with its
// -3 dB frequency prewarped to fd = 2.0775 CFC, so the two passes together have the gain
//   |H(f)| = 1 / (1 + (tan(pi f T) / tan(pi fd T))^4)
// (-3 dB at 1.667 CFC: 100 Hz for CFC 60), which `two_pass_gain` returns for the tests.
//
// Ends: the standard filters a record with enough data before and after the event. A run
// starts at t = 0, often in contact already, so the record is extended at both ends by its
// point reflection about the end value (x(-k) = 2 x(0) - x(k)), which keeps the end value and
// slope and does not invent a step; the extension is as long as the filter's memory
// (4 / (fd T) samples, or the record). The passes run over the extended record and the
// extension is cut off.
// That extension pins the filtered record to its last value: a single sample of height S at
// the end comes through as S, and a light body's ringing (above the CFC's band) sampled at
// the last row is reported as if it were the pulse. Before the end the extension's influence
// dies out with the second-order section's envelope exp(-wd t / sqrt(2)); `end_zone` is the
// time over which it falls to 1 % (sqrt(2) ln(100) / wd: 8.3 ms at CFC 60), after which a
// last-sample spike moves the filtered value by less than 0.5 % of its height (the test).
// Peaks within the end zone depend on how the record is extended, so results.hpp takes the
// peaks before it and names a larger value within it apart.
//
// Sampling: the coefficients need fd T < 1/2; `filter` throws std::invalid_argument beyond.
// Data acquisition practice asks for a sample rate of at least 10 CFC (600 Hz for CFC 60, as
// e.g. the FlexPro CFC filter documentation lists); `adequately_sampled` checks that.
#pragma once

#include <vector>

namespace railcrash::cfc {

/// Second-order section of one pass (J211-1 Appendix C notation).
struct Coefficients {
  double a0 = 0.0, a1 = 0.0, a2 = 0.0;
  double b1 = 0.0, b2 = 0.0;
};

/// Design frequency fd = 2.0775 CFC [Hz].
double design_frequency(double cfc);

/// Coefficients of one pass for the channel class `cfc` at sample interval `interval` [s].
/// Throws std::invalid_argument when cfc <= 0, interval <= 0 or fd T >= 1/2.
Coefficients coefficients(double cfc, double interval);

/// Time before a record's end over which its extension still moves the filtered values by
/// more than 1 % [s] (see Ends above): sqrt(2) ln(100) / (2 pi fd).
double end_zone(double cfc);

/// True when the sample rate is at least 10 CFC.
bool adequately_sampled(double cfc, double interval);

/// The samples (uniform interval [s]) filtered at channel class `cfc`, forward and backward.
std::vector<double> filter(const std::vector<double>& samples, double interval, double cfc);

/// Magnitude of the two-pass filter's response at frequency f [Hz] (see above).
double two_pass_gain(double cfc, double interval, double frequency);

/// The response corridor of SAE J211-1 Figure 1 / ISO 6487 (Table 1, lines a-d) at
/// frequency f [Hz], in dB: the upper and lower limits (lower = -infinity above FN).
struct CorridorLimits {
  double lower_db;
  double upper_db;
};
CorridorLimits corridor(double cfc, double frequency);

/// Values at the uniform times t0, t0 + interval, ... (up to the last time) by linear
/// interpolation of (times, values); times increasing. For records written at a nearly
/// uniform output interval (a failed run's last sample may be off the grid).
std::vector<double> resample_uniform(const std::vector<double>& times, const std::vector<double>& values, double interval);

/// The typical interval of increasing times: the median difference [s] (0 if fewer than 2).
double typical_interval(const std::vector<double>& times);

}  // namespace railcrash::cfc
