// Run results, written to disk as the run goes, kept in memory, or both:
//   DIR/timeseries.csv  t, then <body>.x,<body>.y,<body>.theta,<body>.vx,<body>.vy,<body>.omega for
//                       every body in file order, then <element>.<quantity> columns, then the
//                       output points' columns (results/output_points.hpp), if the run asks
//   DIR/events.csv      t,element,event,value
//   DIR/summary.json    status, message, t_reached, integrator, units, stats, energy, peaks,
//                       peak_accelerations, car_crush (and responses, when the model has them)
// peaks: every element output's signed largest and smallest value over every accepted step,
// both sides of every event and the output samples, with their times:
// {"max", "t_max", "min", "t_min"} (a contact's penetration: max; its gap: min; README).
// In memory (the library's runs, api.hpp): the timeseries.csv columns as vectors and the
// summary.json text; no folder is needed. The writer computes each row once and hands it to
// the run's output sinks (results/output_sink.hpp: csv, hdf5, memory), which format and keep it.
//
// Peak accelerations: every body's acceleration v' at every output sample, from its
// equations of motion  M v' = f(t, q, v) - G^T lambda  (lambda: IDA's multipliers, or the
// penalty forces Euler passes; for Euler they are those of the step just taken, one step
// old). Peaks of |x''|, |y''| and of the magnitude sqrt(x''^2 + y''^2), in the model's units
// and in g (standard gravity 9.80665 m/s^2 = 386.088 in/s^2, whatever the model's gravity).
// Sampled at the output interval: a finer interval sees sharper peaks.
// The same peaks of the accelerations filtered at a channel frequency class (CFC 60 unless
// set_filter_class says otherwise; results/cfc_filter.hpp) are given beside them ("x_cfc",
// "y_cfc", "magnitude_cfc"), taken before the filter's end zone (the last cfc::end_zone
// seconds of the record, 8.3 ms at CFC 60, where the filtered values follow the record's last
// sample rather than its pulse; results/cfc_filter.hpp "Ends"). A larger filtered magnitude
// within the end zone is given apart ("magnitude_cfc_end_zone"): the run may have stopped
// mid-pulse, or a light body rings at the last row. A record no longer than the end zone has
// no such split. The filter reads the accelerations at the output rows, point samples: a light
// body ringing above the rows' Nyquist frequency aliases into the filter's band (at the models'
// own rows, bench/cfc_sampling.py: the two-car crash's draft housings +13 % and +86 %, the
// barrier test's gear housings +53 % and +94 %, the car bodies within 0.4 %). Each body's peak
// is therefore also taken from the mean acceleration over each output interval (velocity
// differences); where the two differ by more than 5 % of the larger (and 0.01 g), the peak
// moves with the output interval and summary.json gives the second one beside it
// ("magnitude_cfc_interval_mean"): lower the output interval until they agree. Then each
// body's collision pulse (first contact, end of its velocity
// change, mean deceleration; results/crash_pulse.hpp) as "collision". The filter needs a
// sample rate of at least 2 x 2.0775 CFC; below 10 CFC the summary says the sampling is too coarse.
// The run folder also gets model.json, accelerations.csv and energy.csv (results/run_files.hpp).
// With the output format hdf5 the four per-row CSV files (timeseries, events, accelerations, energy)
// are datasets of one file instead, DIR/timeseries.h5 (results/hdf5_file.hpp); summary.json's
// "output" then names the format, file and datasets.
//
// Car crush: a car is the set of bodies that declare it with `car: NAME` in the model file
// (bodies without the key, such as a barrier or a track, belong to no car). A model where no
// body declares a car has no per-car crush: summary.json then says so under "cars_note".
// A car's crush is its own shortening, measured between its two ends:
//   crush(t) = L(0) - L(t) + sum over its two ends of share x max(0, crush output(t))
// L is the distance between the car's ends along the track (x; a pitch or sag of the car is
// no crush), L(0) that of the run's first state (after any static settle).
// Each end (towards -x, towards +x) is the outermost point at which the car meets the rest of
// the model through a crush element (OutputRole::Crush: an anticlimber's
// horizontal_deformation, a crush_spring's crush) whose other point lies on ground, on a body
// of no car or on another car, and which faces that way (its other point lies further that
// way; level with it, the point lies on that side of the car's mass centre); an end with no
// such element is the centre of gravity of the car's outermost body on that side. The car's crush elements within the car
// (both points on its bodies) and its body structure (beams, sills) shorten L and need no
// term of their own. An interface element's deformation is not in L: the car takes all of an
// element against ground or a body of no car (a barrier does not crush), and half of one
// between two cars, whose two sides are one law in series (the report's anticlimber: the two
// identical ends in series), so neither side's part can be told from the other: the plane of
// contact is taken midway. The summary gives each car's ends, its largest crush over every
// accepted step, both sides of every event and the output samples, and when.
// The scenario's survival space (results/scenario_criteria.hpp) sums the crush elements' outputs
// instead (CarCrush::elements, shares; car_elements_crush_at).
#pragma once

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "railcrash/core/folder_lock.hpp"
#include "railcrash/core/json_text.hpp"  // json_string, valid_utf8
#include "railcrash/results/crash_pulse.hpp"
#include "railcrash/results/crush_zones.hpp"
#include "railcrash/results/output_sink.hpp"
#include "railcrash/results/provenance.hpp"
#include "railcrash/solver/integrator.hpp"

namespace railcrash {

/// Work space of body_accelerations, kept from one sample to the next (no allocation per row).
struct AccelerationScratch {
  std::vector<double> phi;                      // constraint values
  std::vector<DaeSystem::Triplet> gradient;     // constraint gradient entries
};

/// Body accelerations v' (3 per body: x'', y'', theta'') at a sample state y.
void body_accelerations(const DaeSystem& system, double t, const double* y, const double* lambda, double* acceleration,
                        AccelerationScratch& scratch);
/// The same from the generalized forces at y, which `acceleration` holds on entry
/// (DaeSystem::generalized_forces(t, q, v, f, nullptr, nullptr, lambda)): adds the constraint
/// reactions -G^T lambda and divides by the masses, in place.
void accelerations_from_forces(const DaeSystem& system, const double* y, const double* lambda, double* acceleration,
                               AccelerationScratch& scratch);

/// Standard gravity in the model's units [length/time^2].
double standard_gravity(const Model& model);

/// Largest accelerations of one body over the samples [length/time^2] and when [time].
struct AccelerationPeaks {
  double x = 0.0, t_x = 0.0;
  double y = 0.0, t_y = 0.0;
  double magnitude = 0.0, t_magnitude = 0.0;
};

/// Relative difference of a body's CFC peaks from point samples and from interval means
/// above which the peak is called sampling-sensitive (results.hpp, above).
constexpr double kSamplingSensitivity = 0.05;

/// Filtered peaks and the collision pulse of one body.
struct FilteredAccelerations {
  bool filtered = false;      // false when the samples were too few or too coarse to filter
  AccelerationPeaks peaks;    // of the CFC-filtered accelerations before end_zone_start
  double end_zone_start = 0.0;  // [time] the record's end minus cfc::end_zone; its start when the record is shorter
  AccelerationPeaks end_zone;   // the filtered accelerations' peaks from end_zone_start on (zero when there is no split)
  // The same magnitude peak (before end_zone_start) from each output interval's mean
  // acceleration, (v(t_k) - v(t_k-1)) / (t_k - t_k-1) at the interval's midpoint: a box
  // average in front of the filter, which the point samples above lack (see above).
  double interval_mean_magnitude = 0.0;  // [length/time^2]
  double t_interval_mean = 0.0;          // [time]
  bool sampling_sensitive = false;       // the two peaks differ by more than kSamplingSensitivity
  CollisionPulse collision;   // from the body's x velocity
};

/// One end of a car (results.hpp "Car crush"): a point of one of its bodies and, when the end
/// is an interface crush element's point, that element's crush column and the car's share.
struct CarEnd {
  PointRef point;              // body and body-fixed offset [length]
  std::string element;         // the interface crush element; "" for a body's centre of gravity
  int element_index = -1;      // in the model
  int column = -1;             // its crush output column; -1 for none
  double share = 0.0;          // 1 against ground or a body of no car, 0.5 between two cars
};

/// One car's crush elements, its ends and its largest crush [length] over the run.
struct CarCrush {
  std::string car;
  std::vector<int> bodies;        // body indices, in model order
  // Every crush element acting on the car's bodies (summary.json lists them; the scenario's
  // survival space sums them: car_elements_crush_at).
  std::vector<std::string> elements;
  std::vector<int> element_indices;  // their indices in the model
  std::vector<int> columns;       // output columns of their crush deformations
  std::vector<double> shares;     // 1, or 0.5 for an element between two cars
  std::array<CarEnd, 2> ends;     // towards -x, towards +x of the car's mass centre
  double initial_length = 0.0;    // [length] L(0): x of ends[1] minus x of ends[0] at the run's first state
  double max_crush = 0.0;         // [length]
  double t = 0.0;                 // [time]
};

/// Cars of a model (see above) in the order they are first declared, with their crush elements and ends.
std::vector<CarCrush> cars_of(const DaeSystem& system);

/// Crush of a car at one time [length]: sum of share x max(0, outputs[column]) over its crush
/// output columns (share 1, or 1/2 for an element between two cars). With `allowed` (one stroke
/// [length] per column, infinity for none), each column counts only beyond its allowed stroke:
/// share x max(0, outputs[column] - allowed) (the scenario's survival space beyond the declared
/// crush zones).
double shared_crush(const double* outputs, const std::vector<int>& columns, const std::vector<double>& shares,
                    const std::vector<double>* allowed = nullptr);

/// The car's length L [length] between its ends at state y, along the track (x).
double car_length(const CarCrush& car, const double* y);
/// The car's crush [length] (results.hpp "Car crush") at state y with every output column of y.
double car_crush(const CarCrush& car, const double* y, const double* outputs);

/// The car's crush [length] at state y, an instant at which only the `fresh` columns of
/// `outputs` are y's: at a mode change located inside a step only the changed element's outputs
/// are evaluated again. The car's interface elements whose columns are not fresh are evaluated at
/// y here (into scratch, which is resized to the system's outputs), so that the crush is of one
/// instant. nullopt when the car has interface elements and none of their columns is fresh: the
/// instant is another element's event, and evaluating every car at every event would make a
/// long train's cost grow as N^2.
std::optional<double> car_crush_at(const DaeSystem& system, const CarCrush& car, const double* y, const double* lambda,
                                   const double* outputs, const FreshOutputs& fresh, std::vector<double>& scratch);
/// The sum of the car's crush elements' outputs (shared_crush over CarCrush::columns) at state
/// y, with the same rule for the columns that are not fresh; the scenario's survival space.
std::optional<double> car_elements_crush_at(const DaeSystem& system, const CarCrush& car, const double* y,
                                            const double* lambda, const double* outputs, const FreshOutputs& fresh,
                                            std::vector<double>& scratch, const std::vector<double>* allowed = nullptr);

/// An element output column (index into DaeSystem::output_names()) that plays a role.
struct RoleColumn {
  const Element* element;
  int column;
  int element_index;  // in the model
};
/// Every output playing `role`, in element order.
std::vector<RoleColumn> columns_with_role(const DaeSystem& system, OutputRole role);

/// Column names of timeseries.csv: t, the six body columns per body, the element outputs, the
/// output points' columns (the run's RunSpec::output_points).
std::vector<std::string> timeseries_columns(const DaeSystem& system, const std::vector<OutputPoint>& output_points);
class EnergyWriter;
class BufferedFile;

/// Writes ",value" for every value (as "%.12g") to a CSV row.
void write_row_tail(BufferedFile& file, const double* values, std::size_t count);
void write_row_tail(BufferedFile& file, const std::vector<double>& values);

/// When a run writes its running summary.json again: 2 s of wall time after the last one, or
/// 50 times what writing the last one took, whichever is longer. Its text grows with the model
/// (6 MB at 200 + 200 cars) and a run's length with it, so a fixed interval would cost in
/// proportion to the square of the model; at 50 times, the summaries cost at most 2 % of a run.
class SummarySchedule {
 public:
  using Clock = std::chrono::steady_clock;
  static constexpr Clock::duration kShortestInterval = std::chrono::seconds(2);
  static constexpr int kCostFactor = 50;  // interval / time to write, at least

  explicit SummarySchedule(Clock::time_point start) : last_(start) {}
  bool due(Clock::time_point now) const { return now - last_ > interval_; }
  /// A summary was written, begun and ended at these times.
  void written(Clock::time_point begun, Clock::time_point ended) {
    interval_ = std::max<Clock::duration>(kShortestInterval, kCostFactor * (ended - begun));
    last_ = ended;
  }
  Clock::duration interval() const { return interval_; }

 private:
  Clock::time_point last_;                    // end of the last summary (or the run's start)
  Clock::duration interval_ = kShortestInterval;
};

class ResultWriter : public RunObserver {
 public:
  /// Creates DIR, removes the files an earlier run left in it (run_files.hpp: removed_files()),
  /// and begins the sink of the output format named (results/output_sink.hpp: "csv", each CSV
  /// file with its provenance line (results/provenance.hpp) and its header; "hdf5":
  /// timeseries.h5) (DIR empty: no files). With keep_in_memory, every sample is also kept as
  /// one value per timeseries column (the sink "memory"). run_spec: the run's settings (its
  /// simulation settings go into the provenance, its output points into the timeseries).
  ResultWriter(const std::string& directory, const DaeSystem& system, const RunSpec& run_spec, bool keep_in_memory = false,
               const std::string& format = "csv");
  ~ResultWriter() override;
  ResultWriter(const ResultWriter&) = delete;
  ResultWriter& operator=(const ResultWriter&) = delete;

  void sample(double t, const double* y, const double* lambda, const double* quadratures, const double* outputs) override;
  /// The body accelerations from the run loop's forces (one sweep over the elements per row).
  bool wants_sample_forces() const override { return true; }
  void sample_with_forces(double t, const double* y, const double* lambda, const double* quadratures, const double* outputs,
                          const double* forces) override;
  void event(const EventRecord& record, const double* y) override;
  /// Element output peaks and car crush from every accepted step and both sides of every event:
  /// every output column's (mark_step_columns' default), since the summary's peaks must not
  /// depend on the output interval.
  void step(double t, const double* y, const double* lambda, const double* outputs, const FreshOutputs& fresh) override;
  bool observes_steps() const override { return true; }
  /// The first failed write (file and the OS's reason) or a vanished folder; "" while all is well.
  std::string failure() const override { return failure_; }
  /// The time of the last sample recorded (0 before the first) [time].
  double last_sample_time() const { return t_last_sample_; }
  /// Writes summary.json with "status": "running" (t_reached and peaks so far; stats and
  /// energy come at the end); sample() replaces it every few seconds of wall time.
  void write_running_summary(const std::string& integrator);
  /// Flushes the sinks' files and writes summary.json when there is a folder (call once, at the
  /// end, whatever the outcome); returns its text. Every summary.json is written to a
  /// temporary file in the folder and renamed over the old one, so the file is always whole.
  /// A failed write (also of an earlier row) sets failure().
  std::string write_summary(const RunOutcome& outcome, const std::string& integrator, const std::string& extra_json = "");
  const std::string& directory() const { return directory_; }
  /// This run's provenance (results/provenance.hpp): its id, program, model files and settings.
  const Provenance& provenance() const { return provenance_; }
  /// The files of an earlier run that the constructor removed from the folder (run_files.hpp).
  const std::vector<std::string>& removed_files() const { return removed_files_; }
  /// The kept samples (keep_in_memory): columns[k] is timeseries column k over the samples.
  std::vector<std::vector<double>>& columns() { return kept_columns_ ? *kept_columns_ : no_columns_; }
  /// Peaks so far, per body in model order.
  const std::vector<AccelerationPeaks>& acceleration_peaks() const { return acceleration_peaks_; }
  /// Largest crush of each car so far.
  const std::vector<CarCrush>& car_crush() const { return cars_; }
  /// Energy absorbed per crush zone and per car so far (results/crush_zones.hpp).
  const CrushZoneTracker& crush_zones() const { return *crush_zones_; }
  /// Channel frequency class of the summary's filtered accelerations (default 60).
  void set_filter_class(double cfc) { cfc_ = cfc; }
  double filter_class() const { return cfc_; }
  /// How often, at most, a sample looks whether the output folder still exists (default
  /// 250 ms of wall time; the first sample and the final summary always look). Zero: at every sample.
  void set_folder_check_interval(std::chrono::steady_clock::duration interval) { folder_check_interval_ = interval; }
  /// CFC-filtered peaks and collision pulses per body over the samples so far.
  std::vector<FilteredAccelerations> filtered_accelerations() const;

 private:
  /// What sample() does once acceleration_ holds the body accelerations at the sample.
  void record_sample(double t, const double* y, const double* lambda, const double* quadratures, const double* outputs);

  const DaeSystem& system_;
  std::vector<OutputPoint> output_points_;  // the run's (RunSpec::output_points)
  std::string directory_;
  Provenance provenance_;
  std::unique_ptr<FolderLock> folder_lock_;  // the folder is this run's alone while it writes (null without a folder)
  std::vector<std::string> removed_files_;  // of an earlier run, removed by the constructor
  std::vector<std::unique_ptr<OutputSink>> sinks_;   // where the rows go: the folder's format, then memory
  std::array<bool, kOutputTableCount> table_taken_{};  // by some sink: a table none takes is not computed
  std::vector<std::vector<double>>* kept_columns_ = nullptr;  // the memory sink's, per timeseries column
  std::vector<std::vector<double>> no_columns_;             // columns() without a memory sink
  int folder_descriptor_ = -1;                          // the open folder, to notice its removal
  // Signed largest and smallest value of each element output, and when [time].
  std::vector<double> output_max_, output_min_;
  std::vector<double> t_output_max_, t_output_min_;
  std::vector<double> acceleration_;  // 3 per body at the last sample
  AccelerationScratch acceleration_scratch_;
  std::vector<AccelerationPeaks> acceleration_peaks_;
  std::vector<CarCrush> cars_;
  bool car_lengths_measured_ = false;  // each car's L(0) taken from the first state shown
  std::vector<double> crush_scratch_;  // outputs of a car's crush elements evaluated at an event (car_crush_at)
  std::unique_ptr<EnergyWriter> energy_;  // energy rows (when a sink takes them)
  std::unique_ptr<CrushZoneTracker> crush_zones_;  // energy per crush zone (summary.json, energy_zones.csv)
  std::vector<double> row_;  // one timeseries (or accelerations) row, handed to the sinks
  double cfc_ = 60.0;
  std::vector<double> sample_times_;                  // [time]
  // Per body, per sample, for the filtered peaks and collision pulses at the end; in single
  // precision (7 digits are plenty for peaks) to halve the memory of long, large runs.
  std::vector<std::vector<float>> vx_, ax_, ay_;
  // Per body, the mean accelerations over each output interval (from the second sample on),
  // at the intervals' midpoints; the velocities of the last sample, in double precision.
  std::vector<double> mean_times_;                    // [time]
  std::vector<std::vector<float>> mean_ax_, mean_ay_;
  std::vector<double> last_velocity_;                 // vx, vy per body at the last sample
  std::vector<double> point_values_;                  // output points' columns at the last sample
  // filtered_accelerations() as last computed, over how many samples, with which CFC
  mutable std::vector<FilteredAccelerations> filtered_;
  mutable std::size_t filtered_samples_ = 0;
  mutable double filtered_class_ = 0.0;
  std::chrono::steady_clock::time_point last_flush_;
  SummarySchedule running_summary_;                     // the running summary.json's
  std::chrono::steady_clock::duration folder_check_interval_ = std::chrono::milliseconds(250);
  std::chrono::steady_clock::time_point last_folder_check_;
  bool folder_checked_ = false;                          // by a sample
  std::string integrator_;                               // for the running summary
  double t_last_sample_ = 0.0;                           // [time]
  std::string failure_;                                  // first failed write, with the OS's reason

  /// Peaks of the element outputs and the cars' largest crush, with the outputs at t.
  void track_extrema(double t, const double* y, const double* lambda, const double* outputs, const FreshOutputs& fresh);
  std::string summary_text(const RunOutcome& outcome, const std::string& status, const std::string& integrator,
                           const std::string& extra_json) const;
  /// Writes text to DIR/summary.json through a temporary file and a rename; false (and failure_ set) on error.
  bool replace_summary(const std::string& text);
  /// Checks the sinks' writes (and flushes them with `flush`) and, with `look_at_folder`, that
  /// the folder still exists.
  void check_files(bool flush, bool look_at_folder);
  void fail(const std::string& what, int error_number);
};

/// Number formatted for JSON (non-finite values become null).
std::string json_number(double value);

}  // namespace railcrash
