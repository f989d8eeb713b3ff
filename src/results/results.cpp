#include "railcrash/results/accuracy_check.hpp"
#include "railcrash/results/results.hpp"

#include <algorithm>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cassert>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include "railcrash/core/whole_file.hpp"
#include "railcrash/results/buffered_file.hpp"
#include "railcrash/results/cfc_filter.hpp"
#include "railcrash/results/output_points.hpp"
#include "railcrash/results/provenance.hpp"
#include "railcrash/results/run_files.hpp"

namespace railcrash {

void body_accelerations(const DaeSystem& system, double t, const double* y, const double* lambda, double* acceleration,
                        AccelerationScratch& scratch) {
  const int nq = system.body_unknowns();
  system.generalized_forces(t, y, y + nq, acceleration, nullptr, nullptr, lambda);
  accelerations_from_forces(system, y, lambda, acceleration, scratch);
}

void accelerations_from_forces(const DaeSystem& system, const double* y, const double* lambda, double* acceleration,
                               AccelerationScratch& scratch) {
  const int nq = system.body_unknowns();
  const int m = system.constraint_rows();
  if (m > 0 && lambda != nullptr) {
    scratch.phi.resize(static_cast<std::size_t>(m));
    system.constraints(y, scratch.phi.data(), &scratch.gradient);
    for (const DaeSystem::Triplet& g : scratch.gradient) acceleration[g.col] -= g.value * lambda[g.row];
  }
  for (int k = 0; k < nq; ++k) acceleration[k] /= system.mass_diagonal(k);
}

double standard_gravity(const Model& model) { return model.units == UnitSystem::SI ? 9.80665 : 386.088; }

std::vector<RoleColumn> columns_with_role(const DaeSystem& system, OutputRole role) {
  std::vector<RoleColumn> columns;
  const auto& names = system.output_names();
  const auto& elements = system.model().elements();
  for (std::size_t k = 0; k < elements.size(); ++k) {
    const Element& e = *elements[k];
    const std::string output = e.output_with_role(role);
    if (output.empty()) continue;
    const auto it = std::find(names.begin(), names.end(), e.name() + "." + output);
    RAILCRASH_DEMAND(it != names.end());  // a role names one of the element's outputs
    columns.push_back(RoleColumn{&e, static_cast<int>(it - names.begin()), static_cast<int>(k)});
  }
  return columns;
}

namespace {

/// Global position [length] of a body point at state y (the body's x, y, theta at 3 * body).
std::array<double, 2> point_at(const PointRef& p, const double* y) {
  if (p.body == kGround) return {p.sx, p.sy};
  const double* q = y + 3 * p.body;
  const double c = std::cos(q[2]), s = std::sin(q[2]);
  return {q[0] + c * p.sx - s * p.sy, q[1] + s * p.sx + c * p.sy};
}

}  // namespace

std::vector<CarCrush> cars_of(const DaeSystem& system) {
  const Model& model = system.model();
  std::vector<CarCrush> cars;
  std::vector<int> car_of_body;  // index into cars, -1 for a body of no car
  for (int i = 0; i < model.body_count(); ++i) {
    const std::string& name = model.bodies()[static_cast<std::size_t>(i)].car;
    auto car = std::find_if(cars.begin(), cars.end(), [&](const CarCrush& c) { return c.car == name; });
    if (!name.empty() && car == cars.end()) car = cars.insert(cars.end(), CarCrush{name, {}, {}, {}, {}, {}, {}, 0.0, 0.0, 0.0});
    if (car != cars.end()) car->bodies.push_back(i);
    car_of_body.push_back(name.empty() ? -1 : static_cast<int>(car - cars.begin()));
  }
  const auto car_of = [&](int body) { return body == kGround ? -1 : car_of_body[static_cast<std::size_t>(body)]; };
  std::vector<double> y0(static_cast<std::size_t>(3 * model.body_count()));  // the model file's positions
  for (int i = 0; i < model.body_count(); ++i) {
    const Body& b = model.bodies()[static_cast<std::size_t>(i)];
    y0[static_cast<std::size_t>(3 * i)] = b.x;
    y0[static_cast<std::size_t>(3 * i + 1)] = b.y;
    y0[static_cast<std::size_t>(3 * i + 2)] = b.angle;
  }
  // Each car's interface points: its points of crush elements whose other point is not its
  // own, with the side (-1: towards -x, +1) on which the element's other point lies.
  struct InterfacePoint {
    CarEnd end;
    double side;
  };
  std::vector<std::vector<InterfacePoint>> interface_points(cars.size());
  for (const RoleColumn& crush : columns_with_role(system, OutputRole::Crush)) {
    std::vector<int> touched;
    for (int slot = 0; slot < 2; ++slot) {
      const int car = car_of(crush.element->slot_body(slot));
      if (car >= 0 && std::find(touched.begin(), touched.end(), car) == touched.end()) touched.push_back(car);
    }
    const bool within_one_car = touched.size() == 1 && car_of(crush.element->slot_body(0)) == car_of(crush.element->slot_body(1));
    for (const int c : touched) {
      CarCrush& car = cars[static_cast<std::size_t>(c)];
      car.elements.push_back(crush.element->name());
      car.element_indices.push_back(crush.element_index);
      car.columns.push_back(crush.column);
      car.shares.push_back(1.0 / static_cast<double>(touched.size()));
      if (within_one_car) continue;
      const std::vector<PointRef>& points = crush.element->points();
      for (std::size_t k = 0; k < points.size(); ++k) {
        if (car_of(points[k].body) != c) continue;
        double side = 0.0;  // towards the other points of the element (of another car, ground, ...)
        for (std::size_t other = 0; other < points.size(); ++other)
          if (car_of(points[other].body) != c) side += point_at(points[other], y0.data())[0] - point_at(points[k], y0.data())[0];
        interface_points[static_cast<std::size_t>(c)].push_back(InterfacePoint{
            CarEnd{points[k], crush.element->name(), crush.element_index, crush.column, 1.0 / static_cast<double>(touched.size())},
            side});
      }
    }
  }
  // The ends: on each side the outermost interface point facing that way, or else the centre
  // of gravity of the car's outermost body. An interface point faces the element's other
  // point; one level with it (a vertical contact) faces away from the car's mass centre.
  for (std::size_t c = 0; c < cars.size(); ++c) {
    CarCrush& car = cars[c];
    double mass = 0.0, moment = 0.0;  // [mass], [mass*length]
    for (const int i : car.bodies) {
      mass += model.bodies()[static_cast<std::size_t>(i)].mass;
      moment += model.bodies()[static_cast<std::size_t>(i)].mass * model.bodies()[static_cast<std::size_t>(i)].x;
    }
    const double centre = mass > 0.0 ? moment / mass : model.bodies()[static_cast<std::size_t>(car.bodies.front())].x;
    for (int side = 0; side < 2; ++side) {
      const double sign = side == 0 ? -1.0 : 1.0;  // outward along x
      const CarEnd* outermost = nullptr;
      double reach = 0.0;  // [length] how far out along x
      for (const InterfacePoint& p : interface_points[c]) {
        const double out = sign * (point_at(p.end.point, y0.data())[0] - centre);
        const double facing = p.side != 0.0 ? sign * p.side : out;
        if (facing > 0.0 && (outermost == nullptr || out > reach)) outermost = &p.end, reach = out;
      }
      if (outermost != nullptr) {
        car.ends[static_cast<std::size_t>(side)] = *outermost;
        continue;
      }
      int body = car.bodies.front();
      for (const int i : car.bodies)
        if (sign * model.bodies()[static_cast<std::size_t>(i)].x > sign * model.bodies()[static_cast<std::size_t>(body)].x) body = i;
      car.ends[static_cast<std::size_t>(side)] = CarEnd{PointRef{body, 0.0, 0.0}, "", -1, -1, 0.0};
    }
    car.initial_length = car_length(car, y0.data());
  }
  return cars;
}

double car_length(const CarCrush& car, const double* y) {
  return point_at(car.ends[1].point, y)[0] - point_at(car.ends[0].point, y)[0];  // along the track (x)
}

double car_crush(const CarCrush& car, const double* y, const double* outputs) {
  double crush = car.initial_length - car_length(car, y);  // [length]
  for (const CarEnd& end : car.ends)
    if (end.column >= 0) crush += end.share * std::max(0.0, outputs[end.column]);
  return crush;
}

std::optional<double> car_crush_at(const DaeSystem& system, const CarCrush& car, const double* y, const double* lambda,
                                   const double* outputs, const FreshOutputs& fresh, std::vector<double>& scratch) {
  bool all_fresh = true, any_fresh = false, any_column = false;
  for (const CarEnd& end : car.ends) {
    if (end.column < 0) continue;
    any_column = true;
    all_fresh = all_fresh && fresh.has(end.column);
    any_fresh = any_fresh || fresh.has(end.column);
  }
  if (all_fresh) return car_crush(car, y, outputs);
  if (any_column && !any_fresh) return std::nullopt;
  scratch.resize(system.output_names().size());
  for (const CarEnd& end : car.ends) {
    if (end.column < 0) continue;
    if (fresh.has(end.column)) scratch[static_cast<std::size_t>(end.column)] = outputs[end.column];
    else system.element_outputs(end.element_index, y, lambda, scratch.data());  // at y, here
  }
  return car_crush(car, y, scratch.data());
}

std::optional<double> car_elements_crush_at(const DaeSystem& system, const CarCrush& car, const double* y,
                                            const double* lambda, const double* outputs, const FreshOutputs& fresh,
                                            std::vector<double>& scratch, const std::vector<double>* allowed) {
  if (fresh.has_all(car.columns)) return shared_crush(outputs, car.columns, car.shares, allowed);
  if (std::none_of(car.columns.begin(), car.columns.end(), [&](int column) { return fresh.has(column); }))
    return std::nullopt;
  scratch.resize(system.output_names().size());
  for (std::size_t k = 0; k < car.columns.size(); ++k) {
    const int column = car.columns[k];
    if (fresh.has(column)) scratch[static_cast<std::size_t>(column)] = outputs[column];
    else system.element_outputs(car.element_indices[k], y, lambda, scratch.data());  // at y, here
  }
  return shared_crush(scratch.data(), car.columns, car.shares, allowed);
}

double shared_crush(const double* outputs, const std::vector<int>& columns, const std::vector<double>& shares,
                    const std::vector<double>* allowed) {
  assert(columns.size() == shares.size());
  assert(!allowed || allowed->size() == columns.size());
  double total = 0.0;  // [length]
  for (std::size_t k = 0; k < columns.size(); ++k)
    total += shares[k] * std::max(0.0, outputs[columns[k]] - (allowed ? (*allowed)[k] : 0.0));
  return total;
}

std::string json_number(double value) {
  if (!std::isfinite(value)) return "null";
  char buffer[32];  // the room format_general12 may write into
  return std::string(buffer, format_general12(buffer, value));  // printf's "%.12g", about 10x faster (buffered_file.hpp)
}

std::vector<std::string> timeseries_columns(const DaeSystem& system, const std::vector<OutputPoint>& output_points) {
  std::vector<std::string> names{"t"};
  for (const Body& b : system.model().bodies())
    for (const char* q : {"x", "y", "theta", "vx", "vy", "omega"}) names.push_back(b.name + "." + q);
  for (const std::string& name : system.output_names()) names.push_back(name);
  for (const std::string& name : output_point_columns(output_points)) names.push_back(name);
  return names;
}

ResultWriter::ResultWriter(const std::string& directory, const DaeSystem& system, const RunSpec& run_spec, bool keep_in_memory,
                           const std::string& format)
    : system_(system), output_points_(run_spec.output_points), directory_(directory),
      provenance_(run_provenance(system.model(), run_spec.simulation, new_run_id())),
      last_flush_(std::chrono::steady_clock::now()), running_summary_(last_flush_) {
  const Model& model = system.model();
  const bool si = model.units == UnitSystem::SI;
  const std::string length = si ? "m" : "in";
  OutputLayout layout;
  layout.directory = directory;
  layout.model = &model;
  layout.provenance = &provenance_;
  std::vector<std::string> acceleration_names{"t"};
  for (const Body& b : model.bodies())
    for (const char* q : {"ax", "ay", "alpha"}) acceleration_names.push_back(b.name + "." + q);
  energy_ = std::make_unique<EnergyWriter>(system);
  layout.tables = {OutputTableLayout{"timeseries", timeseries_columns(system, output_points_),
                                     "x, y: " + length + "; theta: rad; vx, vy: " + length +
                                         "/s; omega: rad/s; element outputs: the file's units"},
                   OutputTableLayout{"accelerations", acceleration_names, si ? "m/s^2, rad/s^2" : "in/s^2, rad/s^2"},
                   OutputTableLayout{"energy", energy_->columns(), si ? "J" : "in*lbf"}};
  if (!directory.empty()) {
    std::error_code error;
    std::filesystem::create_directories(directory, error);
    if (error) throw InputError("cannot create the output folder '" + directory + "': " + error.message());
    folder_lock_ = std::make_unique<FolderLock>(directory);  // (throws: another process writes there)
    removed_files_ = remove_earlier_run_files(directory);  // the folder holds this run's files only
    sinks_.push_back(make_output_sink(format));
    sinks_.back()->begin(layout);  // (throws: the files cannot be made)
    write_model_geometry(system, directory + "/model.json", provenance_.run_id);  // (throws: before the folder is held open)
    folder_descriptor_ = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (folder_descriptor_ < 0) throw InputError("cannot open the output folder '" + directory + "': " + std::strerror(errno));
  }
  if (keep_in_memory) {
    sinks_.push_back(make_output_sink("memory"));
    sinks_.back()->begin(layout);
    kept_columns_ = sinks_.back()->kept_columns();
  }
  for (const std::unique_ptr<OutputSink>& sink : sinks_)
    for (std::size_t k = 0; k < kOutputTableCount; ++k) table_taken_[k] = table_taken_[k] || sink->takes(static_cast<OutputTable>(k));
  if (!table_taken_[static_cast<std::size_t>(OutputTable::Energy)]) energy_.reset();  // (its rows cost a sweep over the elements)
  const std::size_t body_count = static_cast<std::size_t>(system.model().body_count());
  vx_.assign(body_count, {});
  ax_.assign(body_count, {});
  ay_.assign(body_count, {});
  mean_ax_.assign(body_count, {});
  mean_ay_.assign(body_count, {});
  last_velocity_.assign(2 * body_count, 0.0);
  output_max_.assign(system.output_names().size(), -std::numeric_limits<double>::infinity());
  output_min_.assign(system.output_names().size(), std::numeric_limits<double>::infinity());
  t_output_max_.assign(system.output_names().size(), 0.0);
  t_output_min_.assign(system.output_names().size(), 0.0);
  acceleration_.assign(static_cast<std::size_t>(system.body_unknowns()), 0.0);
  acceleration_peaks_.assign(static_cast<std::size_t>(system.model().body_count()), AccelerationPeaks{});
  cars_ = cars_of(system);
  crush_zones_ = std::make_unique<CrushZoneTracker>(system);
}

ResultWriter::~ResultWriter() {
  if (folder_descriptor_ >= 0) ::close(folder_descriptor_);
}

void ResultWriter::sample(double t, const double* y, const double* lambda, const double* quadratures, const double* outputs) {
  body_accelerations(system_, t, y, lambda, acceleration_.data(), acceleration_scratch_);
  record_sample(t, y, lambda, quadratures, outputs);
}

void ResultWriter::sample_with_forces(double t, const double* y, const double* lambda, const double* quadratures,
                                      const double* outputs, const double* forces) {
  std::copy(forces, forces + acceleration_.size(), acceleration_.begin());
  accelerations_from_forces(system_, y, lambda, acceleration_.data(), acceleration_scratch_);
  record_sample(t, y, lambda, quadratures, outputs);
}

void ResultWriter::record_sample(double t, const double* y, const double* lambda, const double* quadratures,
                                 const double* outputs) {
  const int n = system_.model().body_count();
  const int nq = 3 * n;
  const std::size_t output_count = system_.output_names().size();
  track_extrema(t, y, lambda, outputs, FreshOutputs{});
  if (!output_points_.empty()) output_point_values(output_points_, y, y + nq, acceleration_.data(), point_values_);
  const auto taken = [&](OutputTable table) { return table_taken_[static_cast<std::size_t>(table)]; };
  const auto hand_on = [&](OutputTable table, const double* values) {
    for (const std::unique_ptr<OutputSink>& sink : sinks_)
      if (sink->takes(table)) sink->row(table, values);
  };
  if (taken(OutputTable::Timeseries)) {  // in the order of the columns (timeseries_columns)
    row_.assign(1, t);
    for (int i = 0; i < n; ++i)
      for (const int k : {3 * i, 3 * i + 1, 3 * i + 2, nq + 3 * i, nq + 3 * i + 1, nq + 3 * i + 2}) row_.push_back(y[k]);
    row_.insert(row_.end(), outputs, outputs + output_count);
    row_.insert(row_.end(), point_values_.begin(), point_values_.end());
    hand_on(OutputTable::Timeseries, row_.data());
  }
  if (taken(OutputTable::Accelerations)) {
    row_.assign(1, t);
    row_.insert(row_.end(), acceleration_.begin(), acceleration_.end());
    hand_on(OutputTable::Accelerations, row_.data());
  }
  if (energy_) {
    energy_->sample(t, y, quadratures);
    hand_on(OutputTable::Energy, energy_->row().data());
  }
  crush_zones_->sample(y, quadratures);
  // The mean over the interval since the last sample, from velocities in double precision.
  const double span = sample_times_.empty() ? 0.0 : t - sample_times_.back();
  if (span > 0.0) mean_times_.push_back(sample_times_.back() + 0.5 * span);
  sample_times_.push_back(t);
  for (int i = 0; i < n; ++i) {
    const std::size_t b = static_cast<std::size_t>(i);
    const double vx = y[nq + 3 * i], vy = y[nq + 3 * i + 1];
    vx_[b].push_back(static_cast<float>(vx));
    ax_[b].push_back(static_cast<float>(acceleration_[3 * b]));
    ay_[b].push_back(static_cast<float>(acceleration_[3 * b + 1]));
    if (span > 0.0) {
      mean_ax_[b].push_back(static_cast<float>((vx - last_velocity_[2 * b]) / span));
      mean_ay_[b].push_back(static_cast<float>((vy - last_velocity_[2 * b + 1]) / span));
    }
    last_velocity_[2 * b] = vx;
    last_velocity_[2 * b + 1] = vy;
  }
  for (int i = 0; i < n; ++i) {
    AccelerationPeaks& p = acceleration_peaks_[static_cast<std::size_t>(i)];
    const double ax = acceleration_[static_cast<std::size_t>(3 * i)], ay = acceleration_[static_cast<std::size_t>(3 * i + 1)];
    const double magnitude = std::hypot(ax, ay);
    if (std::abs(ax) > p.x) { p.x = std::abs(ax); p.t_x = t; }
    if (std::abs(ay) > p.y) { p.y = std::abs(ay); p.t_y = t; }
    if (magnitude > p.magnitude) { p.magnitude = magnitude; p.t_magnitude = t; }
  }
  t_last_sample_ = t;
  // Keep what is on disk current without flushing every row; every write checked.
  if (directory_.empty() || !failure_.empty()) return;
  const auto now = std::chrono::steady_clock::now();
  const bool flush = now - last_flush_ > std::chrono::milliseconds(500);
  const bool look_at_folder = !folder_checked_ || now - last_folder_check_ >= folder_check_interval_;
  check_files(flush, look_at_folder);
  if (flush) last_flush_ = now;
  if (look_at_folder) {
    last_folder_check_ = now;
    folder_checked_ = true;
  }
  if (failure_.empty() && running_summary_.due(now)) {
    write_running_summary(integrator_);
    running_summary_.written(now, std::chrono::steady_clock::now());
  }
}

void ResultWriter::step(double t, const double* y, const double* lambda, const double* outputs, const FreshOutputs& fresh) {
  track_extrema(t, y, lambda, outputs, fresh);
}

void ResultWriter::track_extrema(double t, const double* y, const double* lambda, const double* outputs,
                                 const FreshOutputs& fresh) {
  const auto take = [&](std::size_t k) {
    if (outputs[k] > output_max_[k]) {
      output_max_[k] = outputs[k];
      t_output_max_[k] = t;
    }
    if (outputs[k] < output_min_[k]) {
      output_min_[k] = outputs[k];
      t_output_min_[k] = t;
    }
  };
  const std::size_t first = static_cast<std::size_t>(fresh.begin), end = fresh.end_within(output_max_.size());
  if (fresh.marked == nullptr) {
    for (std::size_t k = first; k < end; ++k) take(k);
  } else {  // (never while this writer observes: it marks every column)
    for (std::size_t k = first; k < end; ++k)
      if (fresh.marked[k] != 0) take(k);
  }
  // L(0) from the run's first state, after any static settle or assembly (results.hpp "Car crush").
  if (!car_lengths_measured_)
    for (CarCrush& car : cars_) car.initial_length = car_length(car, y);
  car_lengths_measured_ = true;
  // A car's crush takes its ends' interface outputs of the state's own instant (car_crush_at).
  for (CarCrush& car : cars_) {
    const std::optional<double> crush = car_crush_at(system_, car, y, lambda, outputs, fresh, crush_scratch_);
    if (crush && *crush > car.max_crush) {
      car.max_crush = *crush;
      car.t = t;
    }
  }
}

void write_row_tail(BufferedFile& file, const double* values, std::size_t count) {
  for (std::size_t k = 0; k < count; ++k) {
    file.character(',');
    file.number(values[k]);
  }
}

void write_row_tail(BufferedFile& file, const std::vector<double>& values) { write_row_tail(file, values.data(), values.size()); }

void ResultWriter::fail(const std::string& what, int error_number) {
  if (failure_.empty()) failure_ = what + ": " + std::strerror(error_number);
}

void ResultWriter::check_files(bool flush, bool look_at_folder) {
  for (const std::unique_ptr<OutputSink>& sink : sinks_) {
    const std::string failed = sink->check(flush);  // (the first failure, with what the files hold)
    if (failure_.empty()) failure_ = failed;
  }
  // One fstat of the open folder (no path lookup): a removed folder (no links left) stops the
  // run. Not at every sample: a system call per row was 11 % of a slider-crank run with 1 ms
  // output (perf, this VM); a file written into a removed folder is still written, so the
  // check at the end (write_summary) catches what the periodic one has not yet.
  if (!look_at_folder) return;
  struct stat folder {};
  if (::fstat(folder_descriptor_, &folder) != 0 || folder.st_nlink == 0)
    fail("the output folder " + directory_ + " is gone", ENOENT);
}

void ResultWriter::write_running_summary(const std::string& integrator) {
  integrator_ = integrator;
  if (directory_.empty() || !failure_.empty()) return;
  RunOutcome so_far;
  so_far.t_reached = t_last_sample_;
  replace_summary(summary_text(so_far, "running", integrator, ""));
}

bool ResultWriter::replace_summary(const std::string& text) {
  // A unique temporary name opened without following links, then a rename (whole_file.hpp): a
  // planted summary.json.tmp or a link named summary.json is never written through.
  const std::string path = directory_ + "/summary.json";
  try {
    write_whole_file(path, text);
  } catch (const FileWriteError& e) {
    fail("cannot write " + e.path(), e.error_number());
    // A full disk: the new file has no room beside the old one, but may have in its place
    // (the summary's size hardly changes). Rewritten in place, without following a link.
    if (e.error_number() != ENOSPC && e.error_number() != EDQUOT) return false;
    const int descriptor = ::open(path.c_str(), O_WRONLY | O_NOFOLLOW | O_CLOEXEC);
    if (descriptor < 0) return false;
    const bool written = ::ftruncate(descriptor, 0) == 0 && write_all(descriptor, text.data(), text.size()) == 0;
    return ::close(descriptor) == 0 && written;
  }
  return true;
}

void ResultWriter::event(const EventRecord& record, const double*) {
  for (const std::unique_ptr<OutputSink>& sink : sinks_) {
    const std::string failed = sink->event(record);
    if (failure_.empty()) failure_ = failed;
  }
}

std::vector<FilteredAccelerations> ResultWriter::filtered_accelerations() const {
  // The final summary and run_model both ask at the end: filter the samples once.
  if (!sample_times_.empty() && filtered_samples_ == sample_times_.size() && filtered_class_ == cfc_) return filtered_;
  std::vector<FilteredAccelerations> result(vx_.size());
  const double interval = cfc::typical_interval(sample_times_);
  const bool can_filter = sample_times_.size() >= 3 && interval > 0.0 && cfc::design_frequency(cfc_) * interval < 0.5;
  // The end zone's samples go to their own peaks (results.hpp); a record no longer than the
  // zone keeps all of its samples in `peaks`.
  const double end_zone_start =
      sample_times_.empty() ? 0.0 : std::max(sample_times_.front(), sample_times_.back() - cfc::end_zone(cfc_));
  const bool split = !sample_times_.empty() && end_zone_start > sample_times_.front();
  const double sensitivity_floor = 0.01 * standard_gravity(system_.model());  // [length/time^2] 0.01 g
  for (std::size_t b = 0; b < vx_.size(); ++b) {
    FilteredAccelerations& f = result[b];
    const auto widen = [](const std::vector<float>& v) { return std::vector<double>(v.begin(), v.end()); };
    f.collision = collision_pulse(sample_times_, widen(vx_[b]));
    if (!can_filter) continue;
    f.filtered = true;
    const std::vector<double> ax = cfc::filter(cfc::resample_uniform(sample_times_, widen(ax_[b]), interval), interval, cfc_);
    const std::vector<double> ay = cfc::filter(cfc::resample_uniform(sample_times_, widen(ay_[b]), interval), interval, cfc_);
    f.end_zone_start = end_zone_start;
    for (std::size_t k = 0; k < ax.size(); ++k) {
      const double t = sample_times_.front() + static_cast<double>(k) * interval;
      const double magnitude = std::hypot(ax[k], ay[k]);
      AccelerationPeaks& peaks = split && t >= f.end_zone_start ? f.end_zone : f.peaks;
      if (std::abs(ax[k]) > peaks.x) { peaks.x = std::abs(ax[k]); peaks.t_x = t; }
      if (std::abs(ay[k]) > peaks.y) { peaks.y = std::abs(ay[k]); peaks.t_y = t; }
      if (magnitude > peaks.magnitude) { peaks.magnitude = magnitude; peaks.t_magnitude = t; }
    }
    // The same magnitude peak from the interval means (results.hpp), before the end zone.
    if (mean_times_.size() >= 3) {
      const std::vector<double> mx = cfc::filter(cfc::resample_uniform(mean_times_, widen(mean_ax_[b]), interval), interval, cfc_);
      const std::vector<double> my = cfc::filter(cfc::resample_uniform(mean_times_, widen(mean_ay_[b]), interval), interval, cfc_);
      for (std::size_t k = 0; k < mx.size(); ++k) {
        const double t = mean_times_.front() + static_cast<double>(k) * interval;
        if (split && t >= f.end_zone_start) break;
        const double magnitude = std::hypot(mx[k], my[k]);
        if (magnitude > f.interval_mean_magnitude) { f.interval_mean_magnitude = magnitude; f.t_interval_mean = t; }
      }
      const double difference = std::abs(f.peaks.magnitude - f.interval_mean_magnitude);
      f.sampling_sensitive = difference > kSamplingSensitivity * std::max(f.peaks.magnitude, f.interval_mean_magnitude) &&
                             difference > sensitivity_floor;
    }
  }
  filtered_ = result;
  filtered_samples_ = sample_times_.size();
  filtered_class_ = cfc_;
  return result;
}

std::string ResultWriter::write_summary(const RunOutcome& outcome, const std::string& integrator, const std::string& extra_json) {
  if (!directory_.empty() && failure_.empty()) check_files(/*flush=*/true, /*look_at_folder=*/true);
  const std::string text = summary_text(outcome, outcome.ok ? "ok" : "failed", integrator, extra_json);
  if (!directory_.empty()) replace_summary(text);  // also after a failed CSV write: the summary may still fit
  if (!directory_.empty())
    for (const std::unique_ptr<OutputSink>& sink : sinks_) {
      const std::string failed = sink->finish(*crush_zones_);
      if (failure_.empty()) failure_ = failed;
    }
  return text;
}

std::string ResultWriter::summary_text(const RunOutcome& outcome, const std::string& status, const std::string& integrator,
                                       const std::string& extra_json) const {
  const Model& model = system_.model();
  const bool si = model.units == UnitSystem::SI;
  const EnergyBalance energy = EnergyBalance::between(outcome.initial_energy, outcome.final_energy);
  const RunStatistics& s = outcome.stats;
  std::ostringstream j;
  j << "{\n";
  j << "  \"status\": " << json_string(status) << ",\n";
  j << "  \"message\": " << json_string(outcome.message) << ",\n";
  j << "  \"model\": " << json_string(model.name) << ",\n";
  j << "  \"run_id\": " << json_string(provenance_.run_id) << ",\n";
  j << "  \"provenance\": " << provenance_json(provenance_) << ",\n";
  j << "  \"t_reached\": " << json_number(outcome.t_reached) << ",\n";
  j << "  \"integrator\": " << json_string(integrator) << ",\n";
  if (!s.hand_over_reason.empty())  // integrator auto: which method ran when, and why
    j << "  \"integrator_used\": {\"method\": "
      << json_string(ida_or_auto_method(s))
      << ", \"euler_from_t\": " << (s.handed_over_at >= 0.0 ? json_number(s.handed_over_at) : "null")
      << ", \"euler_until_t\": " << (s.handed_back_at >= 0.0 ? json_number(s.handed_back_at) : "null")
      << ", \"reason\": " << json_string(s.hand_over_reason) << "},\n";
  for (const std::unique_ptr<OutputSink>& sink : sinks_) j << sink->summary_entry();  // (none for the CSV files)
  j << "  \"units\": {\"system\": " << json_string(unit_system_name(model.units)) << ", \"length\": "
    << json_string(si ? "m" : "in") << ", \"time\": \"s\", \"force\": " << json_string(si ? "N" : "lbf")
    << ", \"mass\": " << json_string(si ? "kg" : "lbf*s^2/in") << ", \"angle\": \"rad\", \"energy\": "
    << json_string(si ? "J" : "in*lbf") << "},\n";
  j << "  \"stats\": {\"steps\": " << s.steps << ", \"residual_evaluations\": " << s.residual_evaluations
    << ", \"jacobian_evaluations\": " << s.jacobian_evaluations << ", \"linear_setups\": " << s.linear_setups
    << ", \"nonlinear_iterations\": " << s.nonlinear_iterations
    << ", \"error_test_failures\": " << s.error_test_failures
    << ", \"nonlinear_convergence_failures\": " << s.nonlinear_convergence_failures << ", \"events\": " << s.events
    << ", \"located_mode_changes\": " << s.root_returns << ", \"reinitializations\": " << s.reinitializations << ", \"wall_seconds\": " << json_number(s.wall_seconds)
    << ", \"last_step\": " << json_number(s.last_step) << ", \"stability_limit\": " << json_number(s.stability_limit)
    << ", \"assembly_correction\": " << json_number(s.assembly_correction)
    << ", \"settling_steps\": " << s.settling_steps << ", \"settling_displacement\": " << json_number(s.settling_displacement)
    << ", \"unknowns\": " << system_.size() << ", \"jacobian_nonzeros\": " << system_.pattern().nonzeros();
  if (s.factor_nonzeros > 0) j << ", \"factor_nonzeros\": " << s.factor_nonzeros;
  if (!s.factor_ordering.empty()) j << ", \"factor_ordering\": " << json_string(s.factor_ordering);
  if (s.newton_iterations_raised_at >= 0.0)
    j << ", \"newton_iterations_raised_at\": " << json_number(s.newton_iterations_raised_at);
  if (s.bdf_order_held_at >= 0.0) j << ", \"bdf_order_held_at\": " << json_number(s.bdf_order_held_at);
  if (s.origin_distance_in_sizes > 0.0) j << ", \"origin_distance_in_sizes\": " << json_number(s.origin_distance_in_sizes);
  if (s.phases_timed) {  // (--timings) exclusive wall seconds per phase, adding up to wall_seconds
    j << ", \"seconds\": {";
    for (int p = 0; p < kPhaseCount; ++p)
      j << (p > 0 ? ", " : "") << json_string(phase_name(static_cast<Phase>(p))) << ": "
        << json_number(s.phase_seconds[static_cast<std::size_t>(p)]);
    j << "}";
  }
  j << "},\n";
  j << "  \"constraint_residual_max\": " << json_number(outcome.max_constraint_residual) << ",\n";
  j << "  \"energy\": {\"kinetic\": " << json_number(energy.kinetic) << ", \"elastic\": " << json_number(energy.elastic)
    << ", \"gravity\": " << json_number(energy.gravity) << ", \"dissipated\": " << json_number(energy.dissipated)
    << ", \"external_work\": " << json_number(energy.external_work) << ", \"initial_total\": "
    << json_number(energy.initial_total) << ", \"integration_drift\": " << json_number(energy.integration_drift())
    << ", \"balance_error\": " << json_number(energy.error())
    << ", \"relative_balance_error\": " << json_number(relative_balance_error(energy, outcome.most_energy_turned_over)) << "},\n";
  j << "  \"accuracy_warnings\": [";  // (results/accuracy_check.hpp: the limits and why)
  const std::vector<std::string> warnings = accuracy_warnings(accuracy_facts(outcome, integrator, model.units));
  for (std::size_t k = 0; k < warnings.size(); ++k) j << (k ? ", " : "") << json_string(warnings[k]);
  j << "],\n";
  const double ke_integral = outcome.quadratures.empty() ? 0.0 : outcome.quadratures[DaeSystem::kKineticIntegral];
  j << "  \"kinetic_energy_integral\": " << json_number(ke_integral) << ",\n";
  j << "  \"peaks\": {";
  for (std::size_t k = 0; k < output_max_.size(); ++k)
    j << (k ? ", " : "") << json_string(system_.output_names()[k]) << ": {\"max\": " << json_number(output_max_[k])
      << ", \"t_max\": " << json_number(t_output_max_[k]) << ", \"min\": " << json_number(output_min_[k])
      << ", \"t_min\": " << json_number(t_output_min_[k]) << "}";
  j << "},\n";
  const double g = standard_gravity(model);
  const std::vector<FilteredAccelerations> filtered = filtered_accelerations();
  const double interval = cfc::typical_interval(sample_times_);
  const bool filtered_any = !filtered.empty() && filtered.front().filtered;
  const bool adequate = cfc::adequately_sampled(cfc_, interval);
  j << "  \"peak_accelerations\": {\"standard_gravity\": " << json_number(g) << ", \"filter\": {\"cfc\": " << json_number(cfc_)
    << ", \"standard\": \"SAE J211-1 / ISO 6487, two-pass Butterworth\", \"sample_interval\": " << json_number(interval)
    << ", \"adequately_sampled\": " << (adequate ? "true" : "false") << ", \"note\": "
    << json_string(!filtered_any ? "too few or too coarse samples to filter: lower the output interval below " +
                                       json_number(0.5 / cfc::design_frequency(cfc_)) + " s"
                   : adequate ? "x_cfc, y_cfc, magnitude_cfc: peaks of the filtered accelerations; unfiltered beside them"
                              : "sample rate below 10 x CFC: filtered peaks are rough, lower the output interval")
    << ", \"end_zone\": " << json_number(cfc::end_zone(cfc_)) << ", \"end_zone_note\": "
    << json_string(filtered_any && filtered.front().end_zone_start > sample_times_.front()
                       ? "the filtered peaks are taken before the last end_zone seconds of the record, where the filter follows "
                         "the record's last sample rather than the pulse; a larger filtered magnitude there is given as "
                         "magnitude_cfc_end_zone (the run may have stopped mid-pulse: lengthen t_end to see it whole)"
                       : "the record is no longer than the filter's end zone: its filtered peaks include the end, where the "
                         "filter follows the record's last sample")
    << ", \"sampling_note\": "
    << json_string("magnitude_cfc filters the accelerations at the output rows; magnitude_cfc_interval_mean, given where it "
                   "differs by more than 5 %, is the same peak from the mean acceleration over each output interval "
                   "(velocity differences): the body's acceleration has content above the rows' Nyquist frequency, which "
                   "the point samples fold into the filter's band; lower the output interval until the two agree")
    << "}, \"bodies\": {";
  const auto peak_json = [&](double value, double t) {
    return "{\"abs_max\": " + json_number(value) + ", \"g\": " + json_number(value / g) + ", \"t\": " + json_number(t) + "}";
  };
  for (std::size_t i = 0; i < acceleration_peaks_.size(); ++i) {
    const AccelerationPeaks& p = acceleration_peaks_[i];
    const FilteredAccelerations& f = filtered[i];
    j << (i ? ", " : "") << json_string(model.bodies()[i].name) << ": {\"x\": {\"abs_max\": " << json_number(p.x)
      << ", \"g\": " << json_number(p.x / g) << ", \"t\": " << json_number(p.t_x) << "}, \"y\": {\"abs_max\": "
      << json_number(p.y) << ", \"g\": " << json_number(p.y / g) << ", \"t\": " << json_number(p.t_y)
      << "}, \"magnitude\": {\"max\": " << json_number(p.magnitude) << ", \"g\": " << json_number(p.magnitude / g)
      << ", \"t\": " << json_number(p.t_magnitude) << "}";
    if (f.filtered)
      j << ", \"x_cfc\": " << peak_json(f.peaks.x, f.peaks.t_x) << ", \"y_cfc\": " << peak_json(f.peaks.y, f.peaks.t_y)
        << ", \"magnitude_cfc\": " << peak_json(f.peaks.magnitude, f.peaks.t_magnitude);
    if (f.filtered && f.end_zone.magnitude > f.peaks.magnitude)
      j << ", \"magnitude_cfc_end_zone\": " << peak_json(f.end_zone.magnitude, f.end_zone.t_magnitude);
    if (f.filtered && f.sampling_sensitive)
      j << ", \"magnitude_cfc_interval_mean\": " << peak_json(f.interval_mean_magnitude, f.t_interval_mean);
    const CollisionPulse& c = f.collision;
    if (c.found)
      j << ", \"collision\": {\"t_start\": " << json_number(c.t_start) << ", \"t_end\": " << json_number(c.t_end)
        << ", \"complete\": " << (c.complete ? "true" : "false") << ", \"velocity_change\": " << json_number(c.velocity_change)
        << ", \"mean_deceleration\": " << json_number(c.mean_deceleration) << ", \"mean_deceleration_g\": "
        << json_number(c.mean_deceleration / g) << "}";
    j << "}";
  }
  j << "}},\n";
  if (cars_.empty())
    j << "  \"cars_note\": \"no body declares a car (the bodies' car: key in the model file): no per-car crush\",\n";
  else
    j << "  \"car_crush_note\": \"each car's shortening between its two ends (initial minus current length along the "
         "line of the ends at the start), plus all of the crush of an end's crush element against ground or a body of no "
         "car and half of one between two cars; an end is the car's outermost point on a crush element shared with "
         "something outside the car, or else the centre of gravity of its outermost body (README, Car crush)\",\n";
  j << "  \"car_crush\": {";
  for (std::size_t c = 0; c < cars_.size(); ++c) {
    const CarCrush& car = cars_[c];
    j << (c ? ", " : "") << json_string(car.car) << ": {\"max_crush\": " << json_number(car.max_crush)
      << ", \"t\": " << json_number(car.t) << ", \"initial_length\": " << json_number(car.initial_length) << ", \"ends\": [";
    for (std::size_t k = 0; k < car.ends.size(); ++k) {
      const CarEnd& end = car.ends[k];
      j << (k ? ", " : "") << "{\"body\": " << json_string(model.bodies()[static_cast<std::size_t>(end.point.body)].name)
        << ", \"at\": [" << json_number(end.point.sx) << ", " << json_number(end.point.sy) << "]";
      if (end.column >= 0) j << ", \"element\": " << json_string(end.element) << ", \"share\": " << json_number(end.share);
      j << "}";
    }
    j << "], \"bodies\": [";
    for (std::size_t k = 0; k < car.bodies.size(); ++k)
      j << (k ? ", " : "") << json_string(model.bodies()[static_cast<std::size_t>(car.bodies[k])].name);
    j << "], \"elements\": [";
    for (std::size_t k = 0; k < car.elements.size(); ++k)
      j << (k ? ", " : "") << "{\"element\": " << json_string(car.elements[k]) << ", \"share\": " << json_number(car.shares[k]) << "}";
    j << "]}";
  }
  j << "},\n  \"crush_zones\": " << crush_zones_->json(si);
  j << extra_json << "\n}\n";
  return j.str();
}

}  // namespace railcrash
