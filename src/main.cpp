// railcrash command line: `railcrash run MODEL ...` and `railcrash check MODEL`.
// Exit status: 0 success, 1 the run failed or was interrupted (results up to then are
// written), 2 bad input (the message names file, line and what to change).
#include <CLI/CLI.hpp>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>

#include "railcrash/batch.hpp"
#include "railcrash/consist.hpp"
#include "railcrash/scenario/en15227.hpp"
#include "railcrash/dae_system.hpp"
#include "railcrash/element_reference.hpp"
#include "railcrash/euler_integrator.hpp"
#include "railcrash/initial_conditions.hpp"
#include "railcrash/results/accuracy_check.hpp"
#include "railcrash/model_io.hpp"
#include "railcrash/model_schema.hpp"
#include "railcrash/run.hpp"
#include "railcrash/readings.hpp"
#include "railcrash/sensitivity.hpp"
#include "railcrash/folder_lock.hpp"
#include "railcrash/sweep.hpp"
#include "railcrash/sweep_mpi.hpp"
#include "railcrash/converge.hpp"
#include "railcrash/report/report.hpp"
#include "railcrash/results/cfc_filter.hpp"
#include "railcrash/results/provenance.hpp"
#include "railcrash/results/run_files.hpp"
#include "railcrash/version.hpp"
#include "railcrash/whole_file.hpp"

#include <sstream>
#include <thread>

#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_interrupt(int) { g_stop.store(true); }

/// From here on SIGINT and SIGTERM raise g_stop: the runs in progress stop at their next step,
/// the results so far are written, and the command exits 1 (as a failed run).
void catch_interrupts() {
  std::signal(SIGINT, on_interrupt);
  std::signal(SIGTERM, on_interrupt);
}

#ifdef RAILCRASH_MPI_PROGRAM
/// `railcrash sweep` started by mpirun or srun: the same command line, run by the MPI build
/// installed beside this executable (CMakeLists.txt: railcrash links no MPI, so that its other
/// commands start without loading it). Returns only when that program cannot be started.
[[noreturn]] void exec_mpi_program(char** argv) {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  const std::filesystem::path program = self.parent_path() / RAILCRASH_MPI_PROGRAM;
  execv(program.c_str(), argv);
  throw railcrash::InputError("sweep under an MPI launcher: cannot start " + program.string() + " (" + std::strerror(errno) +
                              "), the MPI build of railcrash that is built and installed beside it when MPI is found; "
                              "build and install railcrash again, or run the sweep without mpirun (--jobs)");
}
#endif

/// The one check of every numeric command-line option: a finite number within [low, high]
/// (an open end excluded). The message names the value and the option's valid range, e.g.
/// "--speed: 'inf' is not in range: give a finite number greater than 0 and at most 1000 [km/h]"
/// (CLI11 puts the option's name first). Integer options are checked here for their range and
/// by CLI11 for being whole.
CLI::Validator finite_number(double low, double high, bool low_open, bool high_open, const std::string& unit = "") {
  const auto limit = [](double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", value);
    return std::string(text);
  };
  std::string range = "a finite number";
  if (std::isfinite(low)) range += (low_open ? " greater than " : " of at least ") + limit(low);
  if (std::isfinite(high)) range += (std::isfinite(low) ? " and" : "") + std::string(high_open ? " less than " : " at most ") + limit(high);
  if (!unit.empty()) range += " [" + unit + "]";
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        const char* first = text.c_str();
        char* end = nullptr;
        errno = 0;
        const double value = std::strtod(first, &end);
        if (end == first || *end != '\0') return "'" + text + "' is not a number: give " + range;
        const bool inside = std::isfinite(value) && (low_open ? value > low : value >= low) && (high_open ? value < high : value <= high);
        if (!inside) return "'" + text + "' is not in range: give " + range;
        return "";
      },
      range.substr(2), "finite_number");
}

constexpr double kUnbounded = std::numeric_limits<double>::infinity();
constexpr double kMaxJobs = 65536;  // --jobs: threads asked for (batch.cpp runs with those it can have)

int check_command(const std::string& path, const std::vector<std::string>& settings) {
  using namespace railcrash;
  const Model model = load_model(path, settings);
  const DaeSystem system(model);
  std::vector<double> y = system.initial_state();
  AssemblyReport assembly;
  try {
    assembly = assemble_initial_state(system, y);
  } catch (const SolverError& e) {  // exit 1 as in `run`, with the file named
    throw SolverError(SourceLocation{path, 0}.prefix() + e.what());
  }
  // What `run` does next: consistent accelerations and joint reactions at the start. A model
  // whose equations are singular there (a body with zero inertia that no joint holds) cannot
  // run, so `check` refuses it as input.
  std::vector<double> y_start = y, yp_start;
  try {
    consistent_rates(system, 0.0, y_start, yp_start);
  } catch (const SolverError& e) {
    SourceLocation where{path, 0};
    for (const Body& b : model.bodies())
      if (b.inertia == 0.0 && where.line == 0) where = b.where;  // the first body the message names
    throw InputError(where.prefix() + e.what());
  }
  // The element outputs at the start: a run whose first sample has a non-finite one fails.
  std::vector<double> outputs(system.output_names().size());
  system.outputs(y_start.data(), y_start.data() + 2 * system.body_unknowns(), outputs.data());
  for (std::size_t k = 0; k < outputs.size(); ++k)
    if (!std::isfinite(outputs[k])) {
      const std::string& column = system.output_names()[k];  // "<element>.<output>"
      const std::string element = column.substr(0, column.rfind('.'));
      SourceLocation where{path, 0};
      for (const auto& e : model.elements())
        if (e->name() == element) where = e->where();
      throw InputError(where.prefix() + "element '" + element + "': its output '" + column.substr(column.rfind('.') + 1) + "' is " +
                       std::to_string(outputs[k]) + " at t = 0; check the element's numbers (a value too large or too small)");
    }
  int constraint_elements = 0;
  for (const auto& e : model.elements()) constraint_elements += e->constraint_count() > 0;
  std::printf("model      %s  (%s)\n", model.name.c_str(), path.c_str());
  std::printf("units      %s%s, gravity [%g, %g]\n", unit_system_name(model.units),
              model.file_units == unit_system_name(model.units) ? "" : (" (the file's " + model.file_units + ", converted when read)").c_str(),
              model.gravity_x, model.gravity_y);
  const ExpandedModel expanded = expand_model_file(path, settings);  // the cars the file's trains placed
  if (!expanded.cars.empty()) {
    std::printf("cars       %zu placed from car types (railcrash expand writes the flat model)\n", expanded.cars.size());
    for (const ExpandedCar& car : expanded.cars)
      std::printf("  %-20s type %-14s%s leading end x %-10.6g trailing end x %-10.6g %zu bodies, %zu elements\n", car.name.c_str(),
                  car.type.c_str(), car.reversed ? " reversed" : "         ", car.leading_x, car.trailing_x, car.bodies, car.elements);
  }
  std::printf("bodies     %d\n", model.body_count());
  for (const Body& b : model.bodies())
    std::printf("  %-20s mass %-12.6g inertia %-12.6g at [%g, %g]\n", b.name.c_str(), b.mass, b.inertia, b.x, b.y);
  std::printf("elements   %zu (%d constraints)\n", model.elements().size(), constraint_elements);
  for (const auto& e : model.elements())
    std::printf("  %-20s %-20s%s\n", e->name().c_str(), e->type().c_str(),
                e->constraint_count() ? (" " + std::to_string(e->constraint_count()) + " equations").c_str() : "");
  std::printf("loads      %zu\n", model.loads().size());
  std::printf("unknowns   %d  (3 x %d positions, 3 x %d velocities, %d multipliers lambda, %d mu)\n", system.size(),
              model.body_count(), model.body_count(), model.constraint_rows(), model.constraint_rows());
  std::printf("degrees of freedom  %d\n", model.degrees_of_freedom());
  std::printf("jacobian   %d nonzeros (%.3g%% of %d x %d)\n", system.pattern().nonzeros(),
              100.0 * system.pattern().nonzeros() / (static_cast<double>(system.size()) * system.size()), system.size(),
              system.size());
  std::printf("assembly   initial positions moved by at most %.3g, velocities by %.3g\n", assembly.largest_position_change,
              assembly.largest_velocity_change);
  bool all_inertia = true;
  for (const Body& b : model.bodies()) all_inertia = all_inertia && b.inertia > 0.0;
  if (all_inertia) {
    const double limit = EulerIntegrator::estimate_stability_limit(system, y, nullptr);
    std::printf("euler      stability limit of the elements alone: dt < %.4g (joints add penalty springs)\n", limit);
  }
  std::printf("simulation t_end %g, integrator %s\n", model.simulation.t_end, integrator_name(model.simulation.integrator));
  return 0;
}

/// `railcrash elements [TYPE] [--markdown]`: the element reference from the declarations.
int elements_command(const std::string& type_name, bool markdown) {
  using namespace railcrash;
  const ElementRegistry& registry = ElementRegistry::instance();
  if (markdown) {
    if (!type_name.empty()) throw InputError("elements: --markdown prints the whole reference; leave out '" + type_name + "'");
    std::fputs(element_reference_markdown(registry).c_str(), stdout);
    return 0;
  }
  if (type_name.empty()) {
    std::fputs(element_type_list(registry).c_str(), stdout);
    return 0;
  }
  const ElementType* type = registry.find(type_name);
  if (!type) {
    std::string known;
    for (const std::string& name : registry.types()) known += (known.empty() ? "" : ", ") + name;
    throw InputError("elements: unknown element type '" + type_name + "'" + suggestion(type_name, registry.types()) +
                     "; known types: " + known);
  }
  std::fputs(element_type_reference(*type).c_str(), stdout);
  return 0;
}

/// `railcrash report RUN_A RUN_B [...]`: the runs side by side (report.hpp write_comparison).
int compare_command(const std::vector<std::string>& run_dirs, const std::string& out, double force_cfc, bool pdf) {
  railcrash::report::ReportOptions options;
  options.force_cfc = force_cfc;
  options.pdf = pdf;
  const railcrash::report::ReportResult result = railcrash::report::write_comparison(run_dirs, out, options);
  for (const std::string& problem : result.problems) std::fprintf(stderr, "report: %s\n", problem.c_str());
  std::printf("%zu runs side by side written to %s%s\n", result.rows, result.path.c_str(),
              railcrash::report::have_plotting_library() ? "" : " (without charts: this build has no plotting library)");
  if (!result.pdf_path.empty()) std::printf("PDF of the page written to %s\n", result.pdf_path.c_str());
  return 0;
}

int report_command(const std::string& run_dir, double cfc, double force_cfc = 60.0, bool pdf = false) {
  railcrash::report::ReportOptions options;
  options.cfc = cfc;
  options.force_cfc = force_cfc;
  options.pdf = pdf;
  const railcrash::report::ReportResult result = railcrash::report::write_report(run_dir, options);
  for (const std::string& problem : result.problems) std::fprintf(stderr, "report: %s\n", problem.c_str());
  if (!result.study.empty())
    std::printf("report of the %s study (%zu files) written to %s\n", result.study.c_str(), result.rows, result.path.c_str());
  else
    std::printf("report of %zu output rows written to %s%s\n", result.rows, result.path.c_str(),
                railcrash::report::have_plotting_library() ? "" : " (without plots: this build has no plotting library)");
  if (!result.pdf_path.empty()) std::printf("PDF of the report written to %s\n", result.pdf_path.c_str());
  return 0;
}

int run_command(const std::string& path, const std::vector<std::string>& settings, const railcrash::RunOverrides& overrides,
                const std::string& out_dir, bool with_report, bool quiet, const std::string& format, bool timings) {
  using namespace railcrash;
  if (out_dir.empty()) throw InputError(path + ": --out is empty; give the output folder, e.g. --out results");
  require_output_format(format);
  Model model = load_model(path, settings, option_settings(overrides));  // --set, then the run options
  // The folder is this run's: locked against a second writer, then an earlier run's files go
  // (the writer would remove them too), said here.
  const FolderLock folder_lock(out_dir);
  if (const std::string note = folder_lock.removal_note(out_dir); !note.empty()) std::printf("%s\n", note.c_str());
  if (const std::vector<std::string> removed = remove_earlier_run_files(out_dir); !removed.empty()) {
    std::string names;
    for (const std::string& name : removed) names += (names.empty() ? "" : ", ") + name;
    std::printf("removed the files of an earlier run from %s/: %s\n", out_dir.c_str(), names.c_str());
  }
  catch_interrupts();
  const RunReport report = run_model(model, out_dir, &g_stop, !quiet, /*keep_in_memory=*/false, format, timings);
  const RunOutcome& o = report.outcome;
  const EnergyBalance energy = EnergyBalance::between(o.initial_energy, o.final_energy);
  std::printf("%s: %s with %s to t = %g in %.3g s (%ld steps, %ld residual evaluations)\n", model.name.c_str(),
              o.ok ? "finished" : "FAILED", report.integrator.c_str(), o.t_reached, o.stats.wall_seconds, o.stats.steps,
              o.stats.residual_evaluations);
  if (!o.ok) std::printf("reason: %s\n", o.message.c_str());
  if (!o.stats.hand_over_reason.empty()) std::printf("integrator auto: %s\n", o.stats.hand_over_reason.c_str());
  if (o.stats.phases_timed) {
    std::printf("wall time by phase [s]:");
    for (int p = 0; p < kPhaseCount; ++p) {
      const double seconds = o.stats.phase_seconds[static_cast<std::size_t>(p)];
      if (seconds > 0.0)
        std::printf(" %s %.3g (%.0f %%)", phase_name(static_cast<Phase>(p)), seconds,
                    o.stats.wall_seconds > 0.0 ? 100.0 * seconds / o.stats.wall_seconds : 0.0);
    }
    std::printf("\n");
  }
  if (o.stats.stability_limit > 0.0)
    std::printf("euler step %.4g, stability limit %.4g\n", o.stats.last_step, o.stats.stability_limit);
  std::printf("energy: kinetic %.6g, elastic %.6g, gravity %.6g, dissipated %.6g, external work %.6g; integration drift "
              "%.3g of the initial %.6g (energy the integration lost, no element's)\n",
              energy.kinetic, energy.elastic, energy.gravity, energy.dissipated, energy.external_work,
              energy.integration_drift(), energy.initial_total);
  std::printf("largest constraint residual %.3g\n", o.max_constraint_residual);
  for (const std::string& warning : accuracy_warnings(accuracy_facts(o, report.integrator, model.units)))
    std::printf("WARNING accuracy: %s\n", warning.c_str());
  if (report.has_responses) {
    const Responses& r = report.responses;
    std::printf("responses  R1 %.3f (crush)  R2 %.3f (override)  R3 %.3f  override: %s\n", r.r1, r.r2, r.r3,
                r.overridden ? ("yes, at t = " + std::to_string(r.override_time)).c_str() : "no");
  }
  // Each declared car's largest crush and the CFC 60 peak accelerations of its car-body masses
  // (its bodies whose names contain "body" or "end"; every body's are in summary.json).
  if (report.car_crush.empty()) std::printf("no per-car crush: no body declares a car (car: in the model file)\n");
  for (const CarCrush& car : report.car_crush) {
    std::printf("%-10s max crush %.4g at t = %.4g; peak acceleration (CFC 60, unfiltered) [g]:", car.car.c_str(), car.max_crush, car.t);
    std::string at_end;   // the car-body masses whose filtered magnitude is larger within the end zone
    std::string aliased;  // those whose CFC peak moves with the output interval (results.hpp)
    for (const int body : car.bodies) {
      const auto i = static_cast<std::size_t>(body);
      const std::string& name = model.bodies()[i].name;
      if (name.find("body") == std::string::npos && name.find("end") == std::string::npos) continue;
      const double g = standard_gravity(model);
      if (i < report.filtered_accelerations.size() && report.filtered_accelerations[i].filtered) {
        const FilteredAccelerations& f = report.filtered_accelerations[i];
        std::printf(" %s %.3g (%.3g)", name.c_str(), f.peaks.magnitude / g, report.acceleration_peaks[i].magnitude / g);
        char value[64];
        if (f.end_zone.magnitude > f.peaks.magnitude) {
          std::snprintf(value, sizeof value, "%.3g", f.end_zone.magnitude / g);
          at_end += " " + name + " " + value;
        }
        if (f.sampling_sensitive) {
          std::snprintf(value, sizeof value, "%.3g against %.3g", f.peaks.magnitude / g, f.interval_mean_magnitude / g);
          aliased += " " + name + " " + value;
        }
      } else {
        std::printf(" %s %.3g (unfiltered)", name.c_str(), report.acceleration_peaks[i].magnitude / g);
      }
    }
    std::printf("\n");
    if (!at_end.empty())
      std::printf("%-10s larger CFC 60 values within the record's last %.2g ms, where the filter follows the last row "
                  "(lengthen t_end to see whether a pulse peaks there) [g]:%s\n",
                  "", 1e3 * cfc::end_zone(60.0), at_end.c_str());
    if (!aliased.empty())
      std::printf("%-10s CFC 60 peaks from the rows' accelerations against the output intervals' means, more than 5 %% apart "
                  "(the acceleration has content above the rows' Nyquist frequency: lower the output interval) [g]:%s\n",
                  "", aliased.c_str());
  }
  std::printf("results in %s/ (%s, summary.json, model.json), run id %s\n", out_dir.c_str(),
              output_format(format).files,
              report.run_id.c_str());
  if (with_report) report_command(out_dir, 60.0);
  return o.ok ? 0 : 1;
}

int sensitivity_command(const std::string& path, const std::string& design_option, int jobs, double central,
                        const std::string& only, bool first_order_only, double run_limit, std::size_t max_runs,
                        const std::string& out_dir, int bisections, double branch_window_ms) {
  using namespace railcrash;
  check_output_folder(out_dir);
  // "report" (the default): the report's design for this model, sensitivity_design.yaml beside it.
  const std::string design_path = design_option == "report" ? default_design_path(path) : design_option;
  const SensitivityDesign design = load_design(design_path);
  SensitivityOptions options;
  options.jobs = jobs > 0 ? jobs : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  options.central_step = central;
  options.second_order = !first_order_only;
  options.run_time_limit = run_limit;
  options.max_runs = max_runs;
  options.branch_bisections = bisections;
  if (branch_window_ms >= 0.0) options.branch_window = 1e-3 * branch_window_ms;  // else the set of outcomes
  options.progress = [](const SensitivityRun& run, std::size_t number, std::size_t done, std::size_t total) {
    std::string varied = run.variation.empty() ? "base" : "";
    for (const auto& [name, value] : run.variation)
      varied += (varied.empty() ? "" : " ") + name + "=" + std::to_string(value).substr(0, 4);
    std::fprintf(stderr, "[%zu/%zu] run %zu (%s) %s in %.1f s\n", done, total, number, varied.c_str(),
                 run.ok ? "done" : (run.interrupted ? "interrupted" : "FAILED"), run.wall_seconds);
  };
  std::stringstream names(only);
  for (std::string name; std::getline(names, name, ',');)
    if (!name.empty()) options.only.push_back(name);
  options.stop = &g_stop;
  catch_interrupts();
  const auto start = std::chrono::steady_clock::now();
  const SensitivityResult result = run_sensitivity(path, design, options);
  std::string table = write_sensitivity(result, design, out_dir);
  if (design.reference && !result.central && result.base.ok) {
    const std::string comparison = comparison_markdown(result, design);
    std::string text = "# The study against the design's published results\n\n";
    if (result.interrupted)
      text += "**Interrupted after " + std::to_string(result.runs_finished) + " of " + std::to_string(result.runs_total) +
              " runs**: the runs not finished have no results here.\n\n";
    write_whole_file((std::filesystem::path(out_dir) / "comparison.md").string(), text + comparison);
    table += "\n" + comparison;
  }
  std::fputs(table.c_str(), stdout);
  int failed = result.base.ok || result.base.interrupted ? 0 : 1;
  for (const auto& r : result.runs) failed += r.ok || r.interrupted ? 0 : 1;
  for (const auto& r : result.second_order_runs) failed += r.ok || r.interrupted ? 0 : 1;
  std::printf("\n%s: %zu runs with %d jobs in %.1f s; %d failed; results in %s/ (sensitivity.md, sensitivity.csv, "
              "sensitivity_first_order.csv, sensitivity_second_order.csv, sensitivity_derivatives.csv, "
              "sensitivity_ranking.csv%s)\n",
              design_path.c_str(), result.runs.size() + result.second_order_runs.size() + 1, options.jobs,
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), failed, out_dir.c_str(),
              design.reference && !result.central && result.base.ok ? ", comparison.md" : "");
  if (result.interrupted)
    std::printf("interrupted after %zu of %zu runs: the tables hold the finished runs\n", result.runs_finished, result.runs_total);
  return failed == 0 && !result.interrupted ? 0 : 1;
}

int readings_command(const std::string& path, const std::string& design_option, const std::string& readings_path, int jobs,
                     bool first_order_only, double run_limit, std::size_t max_runs, const std::string& out_dir) {
  using namespace railcrash;
  check_output_folder(out_dir);
  const std::string design_path = design_option == "report" ? default_design_path(path) : design_option;
  const SensitivityDesign design = load_design(design_path);
  const ReadingsPlan plan = load_readings(readings_path);
  ReadingsOptions options;
  options.study.jobs = jobs > 0 ? jobs : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  options.study.second_order = !first_order_only;
  options.study.run_time_limit = run_limit;
  options.study.max_runs = max_runs;
  options.progress = [&plan](const ReadingsCombinationResult& r, std::size_t number, std::size_t total) {
    const auto& a = r.agreement.responses;
    std::fprintf(stderr, "[%zu/%zu] %s: R1 %.3f R2 %.3f R3 %.3f; rho R1 %.2f R2 %.2f; goals %d/%d; %d failed; %.0f s\n",
                 number + 1, total, plan.label(r.levels).c_str(), a[0].value, a[1].value, a[2].value, a[0].spearman,
                 a[1].spearman, r.agreement.goals_met, Agreement::kGoals, r.failed_runs, r.wall_seconds);
  };
  options.study.stop = &g_stop;
  catch_interrupts();
  const auto start = std::chrono::steady_clock::now();
  const auto results = run_readings(path, design, plan, options);
  const std::string table = write_readings(results, plan, design, out_dir);
  std::fputs(table.c_str(), stdout);
  int failed = 0;
  for (const auto& r : results) failed += r.failed_runs;
  std::printf("\n%zu combinations x %zu runs with %d jobs in %.1f s; %d runs failed; results in %s/ (readings.md, readings.csv, "
              "combination_NNN/)\n",
              results.size(), results.empty() ? 0 : 1 + results.front().study.runs.size() + results.front().study.second_order_runs.size(),
              options.study.jobs, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), failed,
              out_dir.c_str());
  const std::size_t planned = plan.combination_count().value_or(0);
  const std::size_t complete = static_cast<std::size_t>(
      std::count_if(results.begin(), results.end(), [](const ReadingsCombinationResult& r) { return !r.study.interrupted; }));
  if (complete < planned)
    std::printf("interrupted after %zu of %zu combinations: the tables hold the finished ones%s\n", complete, planned,
                complete < results.size() ? " and the finished runs of the partial one" : "");
  return failed == 0 && complete == planned ? 0 : 1;
}

int converge_command(const std::string& path, const railcrash::ConvergeOptions& options, const std::string& out_dir) {
  using namespace railcrash;
  check_output_folder(out_dir);
  const ConvergePlan plan = plan_convergence(path, options);
  std::printf("convergence study of %s (%s): t_end %g s, output every %g s\n", path.c_str(), plan.model_name.c_str(), plan.t_end,
              plan.output_interval);
  for (const ConvergeQuantity& q : plan.quantities)
    std::printf("  %-24s %s\n", q.name.c_str(), q.applicable ? q.description.c_str() : ("not applicable: " + q.note).c_str());
  if (!plan.euler_steps.empty()) {
    std::printf("euler: stability limit %.4g s (elements), %.4g s with the penalty joints at the first step; steps %.4g s "
                "down to %.4g s (%zu runs); %.3g us per step measured, about %.3g s for the Euler runs on one job\n",
                plan.element_stability_limit, plan.stability_limit, plan.euler_steps.front(), plan.euler_steps.back(), plan.euler_steps.size(),
                1e6 * plan.euler_seconds_per_step, plan.euler_estimate_seconds);
  }
  std::printf("ida: reference rtol %g, runs at rtol", options.reference_rtol);
  for (double r : options.rtols) std::printf(" %g", r);
  std::printf("; %d job%s%s\n", options.jobs, options.jobs > 1 ? "s" : "",
              options.jobs > 1 ? " (wall times are noisier under parallel load)" : "");
  std::fflush(stdout);
  catch_interrupts();
  const auto progress = [](const ConvergeRun& run) {
    char setting[32];
    std::snprintf(setting, sizeof setting, run.method == "euler" ? "dt %.4g" : "rtol %.0e", run.method == "euler" ? run.step : run.rtol);
    std::printf("  %-9s %-12s %-6s %8.3g s  %ld steps%s%s\n", run.method.c_str(), setting, run.ok ? "ok" : "FAILED", run.wall_seconds, run.stats.steps, run.ok ? "" : ": ", run.ok ? "" : run.message.c_str());
    std::fflush(stdout);
  };
  const ConvergeResult result = run_convergence(plan, progress, &g_stop);
  const std::string summary = write_convergence(result, out_dir);
  std::printf("\n%s\nresults in %s/ (converge.csv, converge.svg, converge.md)\n", summary.c_str(), out_dir.c_str());
  if (result.interrupted)
    std::printf("interrupted after %zu of %zu runs: the tables hold the finished runs\n", result.runs_finished, result.runs_total);
  return result.reference.ok && !g_stop.load() ? 0 : 1;
}

/// `sweep --dry-run`: the plan's run count and the levels of the runs listed, generated one at a
/// time (a plan of any size under --max-runs 0), nothing run or written.
int sweep_dry_run_command(const std::string& path, const std::string& plan_path, std::size_t max_runs,
                          std::vector<std::size_t> show_runs) {
  using namespace railcrash;
  const SweepPlan plan = load_sweep_plan(plan_path, path);
  require_sweep_run_count(plan, max_runs);
  const SweepRunGenerator generator(plan, path, read_model_text(path));
  if (show_runs.empty()) {
    for (std::size_t k = 0; k < std::min<std::size_t>(10, generator.count()); ++k) show_runs.push_back(k);
    if (generator.count() > 10) show_runs.push_back(generator.count() - 1);
  }
  std::fputs(sweep_dry_run_text(plan, generator, show_runs).c_str(), stdout);
  return 0;
}

int sweep_command(const std::string& path, const std::string& plan_path, int jobs, double run_limit, bool resume,
                  bool keep_runs, std::size_t max_runs, const std::string& out_dir) {
  using namespace railcrash;
  SweepOptions options;
  options.jobs = jobs > 0 ? jobs : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  options.run_time_limit = run_limit;
  options.resume = resume;
  options.keep_runs = keep_runs;
  options.max_runs = max_runs;
  options.stop = &g_stop;
  options.progress = [](std::size_t number, const SweepRow& row, std::size_t done, std::size_t total) {
    std::fprintf(stderr, "[%zu/%zu] run %zu %s %.2f s%s%s\n", done, total, number, row.status.c_str(), row.wall_seconds,
                 row.message.empty() ? "" : ": ", row.message.c_str());
  };
  options.note = [](const std::string& text) {
    std::fputs(text.c_str(), stdout);
    std::fflush(stdout);
  };
  catch_interrupts();
#ifdef RAILCRASH_MPI
  if (launched_by_mpi()) return sweep_with_mpi(path, plan_path, out_dir, options);
#endif
  check_output_folder(out_dir);
  const SweepPlan plan = load_sweep_plan(plan_path, path);  // every key and level checked before any run
  const auto start = std::chrono::steady_clock::now();
  const SweepResult result = run_sweep(path, plan, out_dir, options);
  const std::size_t failed = failed_sweep_runs(plan, result);
  std::printf("%zu of %zu runs done (%zu resumed), %zu failed, with %d jobs in %.1f s; results in %s/ (runs.csv, summary.md)\n",
              result.done(), result.total, result.resumed, failed, options.jobs,
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), out_dir.c_str());
  if (result.done() < result.total) std::printf("interrupted: run again with --resume to finish\n");
  if (failed > 0) std::printf("%zu run%s failed (status and message in runs.csv)\n", failed, failed == 1 ? "" : "s");
  return result.done() == result.total && failed == 0 && !g_stop.load() ? 0 : 1;
}

/// Writes a generated model to out_path (standard output when empty); `what` names it on stderr.
int write_generated_model(const std::string& text, const std::string& out_path, const std::string& what) {
  if (out_path.empty()) {
    std::fputs(text.c_str(), stdout);
    return 0;
  }
  railcrash::write_whole_file(out_path, text);
  std::fprintf(stderr, "%s written to %s\n", what.c_str(), out_path.c_str());
  return 0;
}

int expand_command(const std::string& path, const std::vector<std::string>& settings, const std::string& out_path, bool out_given) {
  if (out_given) railcrash::check_output_file(out_path);
  const railcrash::ExpandedModel expanded = railcrash::expand_model_file(path, settings);
  return write_generated_model(expanded.text, out_path, "the expanded model (" + std::to_string(expanded.cars.size()) + " cars)");
}

int consist_command(const std::string& template_path, int cars, const std::string& out_path, bool out_given) {
  if (out_given) railcrash::check_output_file(out_path);
  return write_generated_model(railcrash::make_consist_model(template_path, cars), out_path,
                               std::to_string(cars) + " + " + std::to_string(cars) + " cars");
}

/// "mm:kN,mm:kN,..." -> pairs; InputError naming the option otherwise.
std::vector<std::pair<double, double>> parse_curve(const std::string& text, const std::string& option) {
  std::vector<std::pair<double, double>> points;
  std::stringstream items(text);
  std::string item;
  // Each number whole and finite: a stroke from 0 to 10000 mm, a force from 0 to 1e6 kN.
  const auto number = [](const std::string& field, double high, double& value) {
    char* end = nullptr;
    value = std::strtod(field.c_str(), &end);
    return !field.empty() && *end == '\0' && std::isfinite(value) && value >= 0.0 && value <= high;
  };
  while (std::getline(items, item, ',')) {
    const auto colon = item.find(':');
    double stroke = 0.0, force = 0.0;
    if (colon == std::string::npos || !number(item.substr(0, colon), 10000.0, stroke) || !number(item.substr(colon + 1), 1e6, force))
      throw railcrash::InputError(option + ": '" + item + "' is not a point stroke:force (mm:kN) with a stroke from 0 to 10000 mm " +
                                  "and a force from 0 to 1e+06 kN, e.g. 0:0,75:600,105:1500");
    points.emplace_back(stroke, force);
  }
  return points;
}

}  // namespace

int main(int argc, char** argv) {
  railcrash::set_command_line(argc, argv);  // the runs' provenance
  CLI::App app{"railcrash: planar rail-vehicle crash dynamics (IDA + KLU, or explicit Euler)"};
  // The ranges of the numeric options (finite_number: every numeric option has one).
  const CLI::Validator positive = finite_number(0, kUnbounded, true, false);
  const CLI::Validator tolerance = finite_number(0, 1, true, true);
  const CLI::Validator seconds = finite_number(0, kUnbounded, false, false, "s");
  const CLI::Validator job_count = finite_number(0, kMaxJobs, false, false);
  const CLI::Validator run_limit_count = finite_number(0, 1e18, false, false);
  std::size_t max_runs = railcrash::kDefaultMaxRuns;
  app.require_subcommand(1);
  app.set_version_flag("--version", railcrash::version_text());

  std::string model_path, out_dir = "out", integrator;
  std::vector<std::string> settings;
  railcrash::RunOverrides overrides;
  double t_end = 0, rtol = 0, atol = 0, dt = 0, output_interval = 0;

  CLI::App* run = app.add_subcommand("run", "run a model and write DIR/timeseries.csv, events.csv, summary.json");
  run->add_option("model", model_path, "model file (YAML)")->required();
  run->add_option("--integrator", integrator, "auto, ida or euler (default: the model's; a model that names none: auto)")
      ->check(CLI::IsMember({"auto", "ida", "euler"}));
  CLI::Option* t_end_option = run->add_option("--t-end", t_end, "end time");
  // --t-end, --atol, --dt, --output-interval and --max-steps go to the model's simulation keys,
  // whose check refuses a non-finite or out-of-range value naming the model file (model_io.cpp).
  CLI::Option* rtol_option = run->add_option("--rtol", rtol, "ida relative tolerance")->check(tolerance);
  CLI::Option* atol_option = run->add_option("--atol", atol, "ida absolute tolerance on lengths");
  CLI::Option* dt_option = run->add_option("--dt", dt, "euler step");
  CLI::Option* output_option = run->add_option("--output-interval", output_interval, "time between output rows");
  run->add_flag("--force-dt", overrides.force_dt, "euler: run even above the stability limit");
  long max_steps = railcrash::SimulationSettings{}.max_steps;
  CLI::Option* max_steps_option =
      run->add_option("--max-steps", max_steps, "steps either integrator may take; euler refuses a dt that needs more, "
                                                "ida stops there (a failed run)")
          ->capture_default_str();
  run->add_option("--out", out_dir, "output folder")->capture_default_str();
  run->add_option("--set", settings, "override a model key, e.g. --set simulation.t_end=0.5 --set elements.k1.stiffness=2e6");
  bool with_report = false;
  run->add_flag("--report", with_report, "also write DIR/report.html (as `railcrash report DIR`)");
  std::string output_format = "csv";
  run->add_option("--format", output_format, railcrash::output_format_help())
      ->capture_default_str()
      ->check(CLI::IsMember(railcrash::file_output_format_names()));
  bool quiet = false;
  run->add_flag("--quiet", quiet, "no progress (a bar on a terminal, else a line every 5 s, on stderr)");
  bool timings = false;
  double max_output_memory_gb = railcrash::output_memory_limit() / 1e9;
  run->add_option("--max-output-memory", max_output_memory_gb,
                  "refuse a run whose output would keep more memory than this [GB] until its end (0: no limit)")
      ->check(finite_number(0, 1e6, false, false, "GB"));
  run->add_flag("--timings", timings,
                "split the run's wall time by phase (residual, Jacobian, linear solver, events, restarts, output, ...): "
                "printed, and summary.json's stats.seconds");

  std::vector<std::string> report_dirs;
  std::string report_out;
  double report_cfc = 60.0;
  CLI::App* report = app.add_subcommand("report", "write RUN_DIR/report.html: header, animation, event log, plots (one self-contained file); "
                                                  "with two run folders or more, one page of the runs side by side");
  report->add_option("run_dir", report_dirs, "run folder (the --out of `railcrash run`); two or more: the runs side by side, "
                                             "differences to the first")->required();
  report->add_option("--out", report_out, "side by side only: the page's path (default: compare_<A>_<B>.html beside the first run folder)");
  report->add_option("--cfc", report_cfc, "channel frequency class of the acceleration plots (SAE J211-1: 60, 180, 600, 1000)")
      ->capture_default_str()->check(finite_number(60, 1000, false, false, "Hz"));
  double report_force_cfc = 60.0;
  report->add_option("--force-cfc", report_force_cfc,
                     "channel frequency class of the element force plot (SAE J211-1 lists CFC 60 for barrier face forces); 0: unfiltered")
      ->capture_default_str()->check(finite_number(0, 1000, false, false, "Hz"));
  bool report_pdf = false;
  report->add_flag("--pdf", report_pdf, "also print the page to RUN_DIR/report.pdf with headless Chromium (Debian's chromium on PATH)");

  std::string design_path = "report", only;
  int jobs = 0;
  double central = 0.0;
  bool first_order_only = false;
  double run_limit = 0.0;
  CLI::App* sensitivity = app.add_subcommand("sensitivity", "parameter study of R1-R3 (report Section 4)");
  sensitivity->add_option("model", model_path, "model file with a responses section")->required();
  sensitivity->add_option("--design", design_path,
                          "design file: parameters, what they scale, second-order runs and terms; 'report' = "
                          "sensitivity_design.yaml beside the model")
      ->capture_default_str();
  sensitivity->add_option("--jobs", jobs, "runs in parallel (default: all cores)")->check(job_count);
  sensitivity->add_option("--central", central, "central differences at 1 +- H instead of the design's factor")
      ->check(finite_number(0, 1, true, true));
  sensitivity->add_option("--only", only, "comma-separated parameter names to run");
  sensitivity->add_flag("--first-order", first_order_only, "skip the design's second-order runs and fit");
  sensitivity->add_option("--run-limit", run_limit, "stop a run after this many seconds and report it failed (default: no limit)")
      ->check(seconds);
  sensitivity->add_option("--max-runs", max_runs, "refuse a study of more runs than this before it starts (0: no limit)")
      ->capture_default_str()->check(run_limit_count);
  sensitivity->add_option("--out", out_dir, "output folder")->capture_default_str();
  int bisections = 4;
  double branch_window_ms = -1.0;  // not given: runs compare by the set of outcomes
  sensitivity
      ->add_option("--bisect", bisections,
                   "halvings of the step of a first-order run whose discrete outcome differs from run 0's (one run "
                   "each; 0: flag only)")
      ->capture_default_str()
      ->check(CLI::Range(0, 20));
  sensitivity
      ->add_option("--branch-window", branch_window_ms,
                   "[ms] compare the order of the outcomes (fracture, shear, override, bottoming): those this close "
                   "form one group, compared as a set (default: the set of outcomes, order aside)")
      ->check(CLI::NonNegativeNumber);

  std::string readings_path;
  CLI::App* readings = app.add_subcommand(
      "readings", "reading study: the design's whole study for every combination of open readings, scored against "
                  "the published results (report Tables 11-17)");
  readings->add_option("model", model_path, "model file with a responses section")->required();
  readings->add_option("--readings", readings_path, "readings file (YAML: reading_study: 1, readings: [{name, levels}])")->required();
  readings->add_option("--design", design_path, "design file with a 'reference' section; 'report' = sensitivity_design.yaml beside the model")
      ->capture_default_str();
  readings->add_option("--jobs", jobs, "runs in parallel (default: all cores)")->check(job_count);
  readings->add_flag("--first-order", first_order_only, "skip the design's second-order runs");
  readings->add_option("--run-limit", run_limit, "stop a run after this many seconds and report it failed (default: no limit)")
      ->check(seconds);
  readings->add_option("--max-runs", max_runs,
                       "refuse a study of more runs (combinations x runs each) than this before it starts (0: no limit)")
      ->capture_default_str()->check(run_limit_count);
  readings->add_option("--out", out_dir, "output folder")->capture_default_str();

  railcrash::ConvergeOptions converge_options;
  std::string converge_out = "out";
  CLI::App* converge = app.add_subcommand(
      "converge", "convergence study: IDA reference, Euler at halving steps, IDA at tolerances; error versus cost");
  converge->add_option("model", model_path, "model file (YAML)")->required();
  converge->add_option("--quantities", converge_options.quantities,
                       "comma list of max_crush, peak_anticlimber_force, peak_coupler_force, R1, R2, displacement_rms, "
                       "element.NAME.OUTPUT (peak |value|), body.NAME.x|y|theta (displacement at the end), "
                       "event.NAME[:TEXT] (time of the element's first event [whose description contains TEXT]), "
                       "acceleration.BODY (peak CFC-60 acceleration magnitude); default: the first six")
      ->delimiter(',');
  converge->add_option("--euler-steps", converge_options.euler_runs, "number of Euler runs: dt_0 and its halvings (0: none)")
      ->capture_default_str()->check(finite_number(0, 60, false, false));
  converge->add_option("--euler-safety", converge_options.euler_safety, "dt_0 = this x the Euler stability limit")
      ->capture_default_str()->check(finite_number(0, 1, true, true));
  converge->add_option("--euler-dt", converge_options.euler_first_step, "first Euler step instead (must be stable)")->check(positive);
  converge->add_option("--rtols", converge_options.rtols, "comma list of IDA tolerances")->delimiter(',')->capture_default_str()->check(tolerance);
  converge->add_option("--reference-rtol", converge_options.reference_rtol, "IDA reference tolerance")->capture_default_str()->check(tolerance);
  CLI::Option* converge_t_end = converge->add_option("--t-end", t_end, "end time (default: the model's)")->check(positive);
  CLI::Option* converge_output =
      converge->add_option("--output-interval", output_interval, "time between samples (default: the model's)")->check(positive);
  converge->add_option("--headline", converge_options.headline, "quantity for the cost ratio (default: the first applicable)");
  converge->add_option("--levels", converge_options.levels, "comma list of relative error levels for the cost ratio")
      ->delimiter(',')->capture_default_str()->check(finite_number(0, 1, true, false));
  converge->add_option("--jobs", converge_options.jobs,
                       "runs in parallel (default 1: parallel load makes the wall times noisier)")->capture_default_str()
      ->check(finite_number(1, kMaxJobs, false, false));
  converge->add_option("--run-timeout", converge_options.run_time_limit,
                       "stop a run after this many seconds of wall time and report it failed (0: no limit; IDA is stopped "
                       "at its next output time)")
      ->capture_default_str()->check(seconds);
  converge->add_option("--out", converge_out, "output folder")->capture_default_str();
  converge->add_option("--set", settings, "override a model key (KEY=VALUE or KEY*=FACTOR)");

  std::string plan_path;
  bool resume = false, keep_runs = false;
  CLI::App* sweep = app.add_subcommand("sweep", "study over model keys (factorial, one at a time, Latin hypercube, Monte Carlo, "
                                                "run lists): DIR/runs.csv and summary.md; under mpirun the runs go to all ranks");
  sweep->add_option("model", model_path, "model file (YAML)")->required();
  sweep->add_option("--plan", plan_path, "plan file (YAML: sweep: 1, design, factors, responses; README \"Sweeps\")")->required();
  sweep->add_option("--jobs", jobs, "runs in parallel on this machine (default: all cores)")->check(job_count);
  sweep->add_option("--run-limit", run_limit, "stop a run after this many seconds and record it failed (default: no limit)")
      ->check(seconds);
  sweep->add_flag("--resume", resume, "keep the rows of DIR/runs.csv whose run is in the plan (by hash) and run the rest");
  sweep->add_flag("--keep-runs", keep_runs, "also write each run's files to DIR/runs/NNNN/");
  sweep->add_option("--max-runs", max_runs, "refuse a plan of more runs than this before any is generated (0: no limit)")
      ->capture_default_str()->check(run_limit_count);
  sweep->add_option("--out", out_dir, "output folder")->capture_default_str();
  bool sweep_dry_run = false;
  std::vector<std::size_t> sweep_show_runs;
  CLI::Option* dry_run_option = sweep->add_flag("--dry-run", sweep_dry_run,
                  "run nothing: print the plan's run count and the levels of the runs --show-runs lists (default: the "
                  "first 10 and the last), as runs.csv's first columns");
  sweep->add_option("--show-runs", sweep_show_runs, "with --dry-run: the run numbers to print (e.g. 0,1,9999999)")
      ->delimiter(',')
      ->needs(dry_run_option);

  std::string consist_out;
  int consist_cars = 2;
  CLI::App* consist = app.add_subcommand("consist", "write a model of N coupled striking cars into N standing cars, "
                                                    "built from a two-car model (car1_* striking, car2_* standing)");
  consist->add_option("model", model_path, "two-car template, e.g. models/report/final_two_car.yaml")->required();
  consist->add_option("--cars", consist_cars, "cars per consist")->capture_default_str()->check(finite_number(1, 100000, false, false));
  consist->add_option("--out", consist_out, "model file to write (default: standard output)");

  railcrash::ScenarioRequest scenario_request;
  std::string scenario_out, buffer_curve, obstacle_curve;
  std::map<std::string, double> scenario_values;
  CLI::App* scenario = app.add_subcommand("scenario", "write a model of an EN 15227 design collision scenario (1, 2 or 3) "
                                                      "built from a car model, with the criteria evaluated after the run");
  scenario->add_option("number", scenario_request.number, "scenario number (1: two identical trains, 2: 80 t wagon, 3: deformable obstacle)")
      ->required()->check(finite_number(1, 4, false, false));
  scenario->add_option("--train", scenario_request.train_path, "a model with car types and trains (e.g. models/examples/emu3_wall.yaml), a two-car template (car1_* striking, e.g. models/report/final_two_car.yaml) or a model whose bodies declare their cars (e.g. models/barrier/two_car_barrier.yaml)")
      ->required();
  scenario->add_option("--unit", scenario_request.unit, "model with trains: the train to use (default: its first)");
  scenario->add_option("--interface", scenario_request.interface,
                       "model with trains, scenario 1: the interface type joining the two trains' fronts (default: the model's connection there)");
  scenario->add_option("--cars", scenario_request.cars, "cars per train")->capture_default_str()->check(finite_number(1, 1000, false, false));
  scenario->add_option("--category", scenario_request.category, "C-I, C-II, C-III or C-IV")->capture_default_str();
  scenario->add_option("--passenger-bodies", scenario_request.passenger_bodies,
                       "comma list of the passenger-area bodies (template names without car1_), e.g. center_body")->delimiter(',');
  scenario->add_option("--survival-gauge", scenario_request.survival_gauge,
                       "FRONT,REAR: template bodies (without car1_) at the ends of the survival space")->delimiter(',');
  scenario->add_option("--crush-zones", scenario_request.crush_zones,
                       "comma list of declared crush zones NAME or NAME:STROKE [mm]: their crush up to the stroke (default: the end of "
                       "the declared curve) does not count as survival-space loss")->delimiter(',');
  scenario->add_option("--buffer-curve", buffer_curve, "scenario 2: one side buffer's force-stroke curve mm:kN,mm:kN,...");
  scenario->add_option("--wagon-mass", scenario_request.wagon_mass, "scenario 2: wagon mass [t]")->capture_default_str()
      ->check(finite_number(0, 10000, true, false, "t"));
  scenario->add_option("--obstacle-curve", obstacle_curve, "scenario 3: the obstacle's force-crush curve mm:kN,mm:kN,... (required)");
  scenario->add_option("--obstacle-mass", scenario_request.obstacle_mass, "scenario 3: obstacle mass [t]")->capture_default_str()
      ->check(finite_number(0, 10000, true, false, "t"));
  // Each value's valid range: speeds up to 1000 km/h, lengths within 10 m, decelerations up to
  // 100 g, stiffnesses up to 1e6 kN/mm, run times up to 1000 s (EN 15227's collisions last a
  // fraction of a second).
  struct ScenarioValue {
    const char* option;
    const char* help;
    CLI::Validator range;
  };
  const CLI::Validator length_mm = finite_number(0, 10000, false, false, "mm");
  const CLI::Validator stiffness = finite_number(0, 1e6, true, false, "kN/mm");
  for (const ScenarioValue& value : std::vector<ScenarioValue>{
           {"--speed", "closing speed [km/h] (default 36 for C-I)", finite_number(0, 1000, true, false, "km/h")},
           {"--offset", "scenario 1: vertical offset of the standing train [mm] (required)", length_mm},
           {"--deceleration-limit", "mean longitudinal deceleration limit [g] (required)", finite_number(0, 100, true, false, "g")},
           {"--survival-space-limit", "largest allowed shortening of the survival space [mm] (required)", finite_number(0, 10000, true, false, "mm")},
           {"--override-limit", "largest allowed vertical relative displacement at the interface [mm] (required)", finite_number(0, 10000, true, false, "mm")},
           {"--wheel-lift-limit", "largest allowed wheel lift of the leading bogies [mm] (required)", finite_number(0, 10000, true, false, "mm")},
           {"--buffer-unloading-stiffness", "scenario 2: one buffer's unloading stiffness [kN/mm] (required)", stiffness},
           {"--buffer-height", "scenario 2: buffer height above the rail [mm] (required)", length_mm},
           {"--face-stiffness", "scenario 1 from a model declaring its cars: each front face's stiffness [kN/mm] (required)", stiffness},
           {"--face-height", "scenario 1 from a model declaring its cars: each front face's height [mm] (required)", length_mm},
           {"--face-friction", "scenario 1 from a model declaring its cars: friction coefficient between the front faces (required with an offset)",
            finite_number(0, 10, false, false)},
           {"--obstacle-unloading-stiffness", "scenario 3: the obstacle's unloading stiffness [kN/mm] (required)", stiffness},
           {"--obstacle-height", "scenario 3: height of the obstacle's contact point above the rail [mm] (required)", length_mm},
           {"--t-end", "end time of the run [s] (default: the train model's)", finite_number(0, 1000, true, false, "s")}})
    scenario->add_option(value.option, scenario_values[value.option], value.help)->check(value.range);
  scenario->add_option("--out", scenario_out, "model file to write (default: standard output)");

  CLI::App* check = app.add_subcommand("check", "validate a model and print a summary");
  check->add_option("model", model_path, "model file (YAML)")->required();
  check->add_option("--set", settings, "override a model key");

  std::string expand_out;
  CLI::App* expand = app.add_subcommand("expand", "write the model with its car types and trains expanded into flat bodies and elements");
  expand->add_option("model", model_path, "model file (YAML)")->required();
  expand->add_option("--set", settings, "override a model key");
  expand->add_option("--out", expand_out, "model file to write (default: standard output)");

  std::string schema_out;
  CLI::App* schema = app.add_subcommand("schema", "write the JSON Schema of the model file (for editors: README \"Editor support\")");
  schema->add_option("-o,--out", schema_out, "file to write (default: standard output)");

  std::string element_type_name;
  bool elements_markdown = false;
  CLI::App* elements = app.add_subcommand("elements", "element reference: the types, or one type's points and parameters");
  elements->add_option("type", element_type_name, "element type (default: list all types)");
  elements->add_flag("--markdown", elements_markdown, "print the whole reference as Markdown (docs/elements.md)");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    if (*check) return check_command(model_path, settings);
    if (*expand) return expand_command(model_path, settings, expand_out, expand->count("--out") > 0);
    if (*elements) return elements_command(element_type_name, elements_markdown);
    if (*schema) {
      if (schema->count("--out") > 0) railcrash::check_output_file(schema_out);
      return write_generated_model(railcrash::model_schema_json(railcrash::ElementRegistry::instance()), schema_out,
                                   "the model file's JSON Schema");
    }
    if (*report) {
      if (report_dirs.size() > 1) return compare_command(report_dirs, report_out, report_force_cfc, report_pdf);
      if (!report_out.empty())
        throw railcrash::InputError("report --out names the page of runs side by side (two run folders or more); the report of one run "
                                    "is written to " + report_dirs[0] + "/report.html");
      return report_command(report_dirs[0], report_cfc, report_force_cfc, report_pdf);
    }
    if (*consist) return consist_command(model_path, consist_cars, consist_out, consist->count("--out") > 0);
    if (*scenario) {
      if (scenario->count("--out") > 0) railcrash::check_output_file(scenario_out);
      const auto given = [&](const std::string& option) -> std::optional<double> {
        if (scenario->count(option) == 0) return std::nullopt;
        return scenario_values[option];
      };
      scenario_request.speed = given("--speed");
      scenario_request.offset = given("--offset");
      scenario_request.deceleration_limit = given("--deceleration-limit");
      scenario_request.survival_limit = given("--survival-space-limit");
      scenario_request.override_limit = given("--override-limit");
      scenario_request.wheel_lift_limit = given("--wheel-lift-limit");
      scenario_request.buffer_unloading_stiffness = given("--buffer-unloading-stiffness");
      scenario_request.buffer_height = given("--buffer-height");
      scenario_request.face_stiffness = given("--face-stiffness");
      scenario_request.face_height = given("--face-height");
      scenario_request.face_friction = given("--face-friction");
      scenario_request.obstacle_unloading_stiffness = given("--obstacle-unloading-stiffness");
      scenario_request.obstacle_height = given("--obstacle-height");
      scenario_request.t_end = given("--t-end");
      if (!buffer_curve.empty()) scenario_request.buffer_curve = parse_curve(buffer_curve, "--buffer-curve");
      if (!obstacle_curve.empty()) scenario_request.obstacle_curve = parse_curve(obstacle_curve, "--obstacle-curve");
      return write_generated_model(railcrash::make_scenario_model(scenario_request), scenario_out,
                                   "EN 15227 scenario " + std::to_string(scenario_request.number));
    }
    if (*converge) {
      if (*converge_t_end) converge_options.t_end = t_end;
      if (*converge_output) converge_options.output_interval = output_interval;
      converge_options.settings = settings;
      return converge_command(model_path, converge_options, converge_out);
    }
#ifdef RAILCRASH_MPI_PROGRAM
    if (*sweep && railcrash::launched_by_mpi()) exec_mpi_program(argv);
#endif
    if (*sweep && sweep_dry_run) return sweep_dry_run_command(model_path, plan_path, max_runs, sweep_show_runs);
    if (*sweep) return sweep_command(model_path, plan_path, jobs, run_limit, resume, keep_runs, max_runs, out_dir);
    if (*readings) return readings_command(model_path, design_path, readings_path, jobs, first_order_only, run_limit, max_runs, out_dir);
    if (*sensitivity) return sensitivity_command(model_path, design_path, jobs, central, only, first_order_only, run_limit, max_runs, out_dir,
                                                   bisections, branch_window_ms);
    if (!integrator.empty())
      overrides.integrator = railcrash::integrator_from_name(integrator);
    if (*t_end_option) overrides.t_end = t_end;
    if (*rtol_option) overrides.rtol = rtol;
    if (*atol_option) overrides.atol = atol;
    if (*dt_option) overrides.dt = dt;
    if (*output_option) overrides.output_interval = output_interval;
    if (*max_steps_option) overrides.max_steps = max_steps;
    railcrash::set_output_memory_limit(max_output_memory_gb * 1e9);
    return run_command(model_path, settings, overrides, out_dir, with_report, quiet, output_format, timings);
  } catch (const railcrash::InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "railcrash failed: %s\n", e.what());
    return 1;
  }
}
