// `railcrash run MODEL`: one run, its files in --out and a summary printed.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "command.hpp"
#include "common.hpp"
#include "railcrash/core/folder_lock.hpp"
#include "railcrash/model/model_io.hpp"
#include "railcrash/results/accuracy_check.hpp"
#include "railcrash/results/cfc_filter.hpp"
#include "railcrash/results/output_sink.hpp"
#include "railcrash/results/run.hpp"
#include "railcrash/results/run_files.hpp"
#include "railcrash/solver/dae_system.hpp"

namespace railcrash::cli {

namespace {

int run_and_print(const std::string& path, const std::vector<std::string>& settings, const railcrash::RunOverrides& overrides,
                    const std::string& out_dir, bool with_report, bool quiet, const std::string& format, bool timings) {
  using namespace railcrash;
  if (out_dir.empty()) throw InputError(path + ": --out is empty; give the output folder, e.g. --out results");
  require_output_format(format);
  const LoadedModel loaded = load_model(path, settings, option_settings(overrides));  // --set, then the run options
  const Model& model = loaded.model;
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
  const RunReport report = run_model(model, loaded.run_spec, out_dir, &interrupted(), !quiet, /*keep_in_memory=*/false, format, timings);
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
  if (o.stats.stability_limit > 0.0 && o.stats.handed_back_at < 0.0)  // (Euler ended the run)
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
  if (with_report) write_run_report(out_dir, 60.0);
  return o.ok ? 0 : 1;
}

class RunCommand final : public Command {
 public:
  CLI::App* add_to(CLI::App& program) override {
    CLI::App* command = program.add_subcommand("run", "run a model and write DIR/timeseries.csv, events.csv, summary.json");
    command->add_option("model", model_path_, "model file (YAML)")->required();
    command->add_option("--integrator", integrator_, "auto, ida or euler (default: the model's; a model that names none: auto)")
        ->check(CLI::IsMember(railcrash::integrator_names()));
    t_end_option_ = command->add_option("--t-end", t_end_, "end time");
    // --t-end, --atol, --dt, --output-interval and --max-steps go to the model's simulation keys,
    // whose check refuses a non-finite or out-of-range value naming the model file (model_io.cpp).
    rtol_option_ = command->add_option("--rtol", rtol_, "ida relative tolerance")->check(tolerance_range());
    atol_option_ = command->add_option("--atol", atol_, "ida absolute tolerance on lengths");
    dt_option_ = command->add_option("--dt", dt_, "euler step");
    output_option_ = command->add_option("--output-interval", output_interval_, "time between output rows");
    command->add_flag("--force-dt", overrides_.force_dt, "euler: run even above the stability limit");
    max_steps_option_ =
        command->add_option("--max-steps", max_steps_, "steps either integrator may take; euler refuses a dt that needs more, "
                                                       "ida stops there (a failed run)")
            ->capture_default_str();
    add_out_folder_option(*command, out_dir_);
    add_set_option(*command, settings_);
    command->add_flag("--report", with_report_, "also write DIR/report.html (as `railcrash report DIR`)");
    command->add_option("--format", output_format_, output_format_help())
        ->capture_default_str()
        ->check(CLI::IsMember(file_output_format_names()));
    command->add_flag("--quiet", quiet_, "no progress (a bar on a terminal, else a line every 5 s, on stderr)");
    command->add_option("--max-output-memory", max_output_memory_gb_,
                        "refuse a run whose output would keep more memory than this [GB] until its end (0: no limit)")
        ->check(finite_number(0, 1e6, false, false, "GB"));
    command->add_flag("--timings", timings_,
                      "split the run's wall time by phase (residual, Jacobian, linear solver, events, restarts, output, ...): "
                      "printed, and summary.json's stats.seconds");
    return command;
  }

  int run(char** /*argv*/) override {
    if (!integrator_.empty())
      overrides_.integrator = integrator_from_name(integrator_);
    if (*t_end_option_) overrides_.t_end = t_end_;
    if (*rtol_option_) overrides_.rtol = rtol_;
    if (*atol_option_) overrides_.atol = atol_;
    if (*dt_option_) overrides_.dt = dt_;
    if (*output_option_) overrides_.output_interval = output_interval_;
    if (*max_steps_option_) overrides_.max_steps = max_steps_;
    set_output_memory_limit(max_output_memory_gb_ * 1e9);
    return run_and_print(model_path_, settings_, overrides_, out_dir_, with_report_, quiet_,
                         output_format_, timings_);
  }

 private:
  std::string model_path_, out_dir_, integrator_;
  std::vector<std::string> settings_;
  RunOverrides overrides_;
  double t_end_ = 0, rtol_ = 0, atol_ = 0, dt_ = 0, output_interval_ = 0;
  long max_steps_ = SimulationSettings{}.max_steps;
  bool with_report_ = false, quiet_ = false, timings_ = false;
  std::string output_format_ = "csv";
  double max_output_memory_gb_ = output_memory_limit() / 1e9;
  CLI::Option* t_end_option_ = nullptr;
  CLI::Option* rtol_option_ = nullptr;
  CLI::Option* atol_option_ = nullptr;
  CLI::Option* dt_option_ = nullptr;
  CLI::Option* output_option_ = nullptr;
  CLI::Option* max_steps_option_ = nullptr;
};

}  // namespace

std::unique_ptr<Command> make_run_command() { return std::make_unique<RunCommand>(); }

}  // namespace railcrash::cli
