// Run results on disk, written as the run goes:
//   DIR/timeseries.csv  t, then <body>.x,<body>.y,<body>.theta,<body>.vx,<body>.vy,<body>.omega for
//                       every body in file order, then <element>.<quantity> columns
//   DIR/events.csv      t,element,event,value
//   DIR/summary.json    status, message, t_reached, integrator, units, stats, energy, peaks
#pragma once

#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "railcrash/integrator.hpp"

namespace railcrash {

class ResultWriter : public RunObserver {
 public:
  /// Creates DIR and the two CSV files with their headers.
  ResultWriter(const std::string& directory, const DaeSystem& system);
  ~ResultWriter() override;
  ResultWriter(const ResultWriter&) = delete;
  ResultWriter& operator=(const ResultWriter&) = delete;

  void sample(double t, const double* y, const double* lambda, const double* quadratures) override;
  void event(const EventRecord& record, const double* y) override;
  /// Writes summary.json (call once, at the end, whatever the outcome).
  void write_summary(const RunOutcome& outcome, const std::string& integrator, const std::string& extra_json = "");
  const std::string& directory() const { return directory_; }

 private:
  const DaeSystem& system_;
  std::string directory_;
  std::FILE* timeseries_ = nullptr;
  std::FILE* events_ = nullptr;
  std::vector<double> output_values_;
  std::vector<double> peak_output_;  // largest |value| of each element output
  std::vector<double> peak_time_;
  std::chrono::steady_clock::time_point last_flush_;
};

/// Minimal JSON string escaping.
std::string json_string(const std::string& text);
/// Number formatted for JSON (non-finite values become null).
std::string json_number(double value);

}  // namespace railcrash
