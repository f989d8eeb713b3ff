// Run results, written to disk as the run goes, kept in memory, or both:
//   DIR/timeseries.csv  t, then <body>.x,<body>.y,<body>.theta,<body>.vx,<body>.vy,<body>.omega for
//                       every body in file order, then <element>.<quantity> columns
//   DIR/events.csv      t,element,event,value
//   DIR/summary.json    status, message, t_reached, integrator, units, stats, energy, peaks,
//                       peak_accelerations, car_crush (and responses, when the model has them)
// In memory (the library's runs, api.hpp): the timeseries.csv columns as vectors and the
// summary.json text; no folder is needed.
//
// Peak accelerations: every body's acceleration v' at every output sample, from its
// equations of motion  M v' = f(t, q, v) - G^T lambda  (lambda: IDA's multipliers, or the
// penalty forces Euler passes; for Euler they are those of the step just taken, one step
// old). Peaks of |x''|, |y''| and of the magnitude sqrt(x''^2 + y''^2), in the model's units
// and in g (standard gravity 9.80665 m/s^2 = 386.088 in/s^2, whatever the model's gravity).
// Sampled at the output interval: a finer interval sees sharper peaks.
//
// Car crush: a car is the set of bodies whose names start with the same "car<N>_" prefix
// (car1_coupler, car1_front_end, ... form car1); a model without such names is one car,
// "car". The crush of a car is the sum of the crush deformations of the crush elements that
// act on its bodies: an anticlimber's horizontal_deformation (positive part) and a
// crush_spring's crush. An element between two cars gives half of its deformation to each
// (the report's anticlimber carries the two identical ends in series); one between a car
// and ground or within a car, all of it. The summary gives each car's largest crush over
// the output samples and when.
#pragma once

#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "railcrash/integrator.hpp"

namespace railcrash {

/// Body accelerations v' (3 per body: x'', y'', theta'') at a sample state y.
void body_accelerations(const DaeSystem& system, double t, const double* y, const double* lambda, double* acceleration);

/// Standard gravity in the model's units [length/time^2].
double standard_gravity(const Model& model);

/// Largest accelerations of one body over the samples [length/time^2] and when [time].
struct AccelerationPeaks {
  double x = 0.0, t_x = 0.0;
  double y = 0.0, t_y = 0.0;
  double magnitude = 0.0, t_magnitude = 0.0;
};

/// One car's crush elements and its largest crush [length] over the samples.
struct CarCrush {
  std::string car;
  std::vector<std::string> elements;
  std::vector<int> columns;       // output columns of their crush deformations
  std::vector<double> shares;     // 1, or 0.5 for an element between two cars
  double max_crush = 0.0;         // [length]
  double t = 0.0;                 // [time]
};

/// Cars of a model (see above), with their crush elements.
std::vector<CarCrush> cars_of(const DaeSystem& system);

/// Column names of timeseries.csv: t, the six body columns per body, the element outputs.
std::vector<std::string> timeseries_columns(const DaeSystem& system);

class ResultWriter : public RunObserver {
 public:
  /// Creates DIR and the two CSV files with their headers (DIR empty: no files). With
  /// keep_in_memory, every sample is also kept as one value per timeseries column.
  ResultWriter(const std::string& directory, const DaeSystem& system, bool keep_in_memory = false);
  ~ResultWriter() override;
  ResultWriter(const ResultWriter&) = delete;
  ResultWriter& operator=(const ResultWriter&) = delete;

  void sample(double t, const double* y, const double* lambda, const double* quadratures) override;
  void event(const EventRecord& record, const double* y) override;
  /// Writes summary.json when there is a folder (call once, at the end, whatever the
  /// outcome); returns its text.
  std::string write_summary(const RunOutcome& outcome, const std::string& integrator, const std::string& extra_json = "");
  const std::string& directory() const { return directory_; }
  /// The kept samples (keep_in_memory): columns[k] is timeseries column k over the samples.
  std::vector<std::vector<double>>& columns() { return columns_; }
  /// Peaks so far, per body in model order.
  const std::vector<AccelerationPeaks>& acceleration_peaks() const { return acceleration_peaks_; }
  /// Largest crush of each car so far.
  const std::vector<CarCrush>& car_crush() const { return cars_; }

 private:
  const DaeSystem& system_;
  std::string directory_;
  std::FILE* timeseries_ = nullptr;
  std::FILE* events_ = nullptr;
  std::vector<std::vector<double>> columns_;  // in memory, per timeseries column
  std::vector<double> output_values_;
  std::vector<double> peak_output_;  // largest |value| of each element output
  std::vector<double> peak_time_;
  std::vector<double> acceleration_;  // 3 per body at the last sample
  std::vector<AccelerationPeaks> acceleration_peaks_;
  std::vector<CarCrush> cars_;
  std::chrono::steady_clock::time_point last_flush_;
};

/// Minimal JSON string escaping.
std::string json_string(const std::string& text);
/// Number formatted for JSON (non-finite values become null).
std::string json_number(double value);

}  // namespace railcrash
