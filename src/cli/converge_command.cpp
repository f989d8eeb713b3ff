// `railcrash converge MODEL`: the convergence study (IDA reference, Euler at halving steps, IDA
// at tolerances; error versus cost).
#include <cstdio>
#include <string>
#include <vector>

#include "command.hpp"
#include "common.hpp"
#include "railcrash/studies/batch.hpp"
#include "railcrash/studies/converge.hpp"

namespace railcrash::cli {

namespace {

int run_convergence_study(const std::string& path, const railcrash::ConvergeOptions& options, const std::string& out_dir) {
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
  const ConvergeResult result = run_convergence(plan, progress, &interrupted());
  const std::string summary = write_convergence(result, out_dir);
  std::printf("\n%s\nresults in %s/ (converge.csv, converge.svg, converge.md)\n", summary.c_str(), out_dir.c_str());
  if (result.interrupted)
    std::printf("interrupted after %zu of %zu runs: the tables hold the finished runs\n", result.runs_finished, result.runs_total);
  return result.reference.ok && !interrupted().load() ? 0 : 1;
}

class ConvergeCommand final : public Command {
 public:
  CLI::App* add_to(CLI::App& program) override {
    CLI::App* command = program.add_subcommand(
        "converge", "convergence study: IDA reference, Euler at halving steps, IDA at tolerances; error versus cost");
    command->add_option("model", model_path_, "model file (YAML)")->required();
    command->add_option("--quantities", options_.quantities,
                        "comma list of max_crush, peak_anticlimber_force, peak_coupler_force, R1, R2, displacement_rms, "
                        "element.NAME.OUTPUT (peak |value|), body.NAME.x|y|theta (displacement at the end), "
                        "event.NAME[:TEXT] (time of the element's first event [whose description contains TEXT]), "
                        "acceleration.BODY (peak CFC-60 acceleration magnitude); default: the first six")
        ->delimiter(',');
    command->add_option("--euler-steps", options_.euler_runs, "number of Euler runs: dt_0 and its halvings (0: none)")
        ->capture_default_str()->check(finite_number(0, 60, false, false));
    command->add_option("--euler-safety", options_.euler_safety, "dt_0 = this x the Euler stability limit")
        ->capture_default_str()->check(finite_number(0, 1, true, true));
    command->add_option("--euler-dt", options_.euler_first_step, "first Euler step instead (must be stable)")->check(positive_number());
    command->add_option("--rtols", options_.rtols, "comma list of IDA tolerances")->delimiter(',')->capture_default_str()->check(tolerance_range());
    command->add_option("--reference-rtol", options_.reference_rtol, "IDA reference tolerance")->capture_default_str()->check(tolerance_range());
    t_end_option_ = command->add_option("--t-end", t_end_, "end time (default: the model's)")->check(positive_number());
    output_option_ =
        command->add_option("--output-interval", output_interval_, "time between samples (default: the model's)")->check(positive_number());
    command->add_option("--headline", options_.headline, "quantity for the cost ratio (default: the first applicable)");
    command->add_option("--levels", options_.levels, "comma list of relative error levels for the cost ratio")
        ->delimiter(',')->capture_default_str()->check(finite_number(0, 1, true, false));
    add_jobs_option(*command, options_.jobs, JobsDefault::OneForWallTimes);
    add_run_limit_option(*command, options_.run_time_limit, "--run-timeout");
    add_out_folder_option(*command, out_dir_);
    add_set_option(*command, options_.settings);
    return command;
  }

  int run(char** /*argv*/) override {
    if (*t_end_option_) options_.t_end = t_end_;
    if (*output_option_) options_.output_interval = output_interval_;
    return run_convergence_study(model_path_, options_, out_dir_);
  }

 private:
  std::string model_path_, out_dir_;
  ConvergeOptions options_;
  double t_end_ = 0, output_interval_ = 0;
  CLI::Option* t_end_option_ = nullptr;
  CLI::Option* output_option_ = nullptr;
};

}  // namespace

std::unique_ptr<Command> make_converge_command() { return std::make_unique<ConvergeCommand>(); }

}  // namespace railcrash::cli
