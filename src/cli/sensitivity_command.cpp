// `railcrash sensitivity MODEL`: the parameter study of R1-R3 (report Section 4).
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>

#include "command.hpp"
#include "common.hpp"
#include "railcrash/core/whole_file.hpp"
#include "railcrash/studies/readings.hpp"  // comparison_markdown
#include "railcrash/studies/run_count.hpp"
#include "railcrash/studies/sensitivity.hpp"

namespace railcrash::cli {

namespace {

int run_sensitivity_study(const std::string& path, const std::string& design_option, int jobs, double central,
                          const std::string& only, bool first_order_only, double run_limit, std::size_t max_runs,
                          const std::string& out_dir, int bisections, double branch_window_ms) {
  using namespace railcrash;
  check_output_folder(out_dir);
  // "report" (the default): the report's design for this model, sensitivity_design.yaml beside it.
  const std::string design_path = design_option == "report" ? default_design_path(path) : design_option;
  const SensitivityDesign design = load_design(design_path);
  SensitivityOptions options;
  options.jobs = jobs_to_run(jobs);
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
  options.stop = &interrupted();
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

class SensitivityCommand final : public Command {
 public:
  CLI::App* add_to(CLI::App& program) override {
    CLI::App* command = program.add_subcommand("sensitivity", "parameter study of R1-R3 (report Section 4)");
    command->add_option("model", model_path_, "model file with a responses section")->required();
    add_design_option(*command, design_path_);
    add_jobs_option(*command, jobs_, JobsDefault::AllCores);
    command->add_option("--central", central_, "central differences at 1 +- H instead of the design's factor")
        ->check(finite_number(0, 1, true, true));
    command->add_option("--only", only_, "comma-separated parameter names to run");
    add_first_order_option(*command, first_order_only_);
    add_run_limit_option(*command, run_limit_);
    add_max_runs_option(*command, max_runs_);
    add_out_folder_option(*command, out_dir_);
    command
        ->add_option("--bisect", bisections_,
                     "halvings of the step of a first-order run whose discrete outcome differs from run 0's (one run "
                     "each; 0: flag only)")
        ->capture_default_str()
        ->check(CLI::Range(0, 20));
    command
        ->add_option("--branch-window", branch_window_ms_,
                     "[ms] compare the order of the outcomes (fracture, shear, override, bottoming): those this close "
                     "form one group, compared as a set (default: the set of outcomes, order aside)")
        ->check(CLI::NonNegativeNumber);
    return command;
  }

  int run(char** /*argv*/) override {
    return run_sensitivity_study(model_path_, design_path_, jobs_, central_, only_, first_order_only_, run_limit_, max_runs_, out_dir_,
                                 bisections_, branch_window_ms_);
  }

 private:
  std::string model_path_, design_path_, only_, out_dir_;
  int jobs_ = 0;
  double central_ = 0.0;
  bool first_order_only_ = false;
  double run_limit_ = 0.0;
  std::size_t max_runs_ = kDefaultMaxRuns;
  int bisections_ = 4;
  double branch_window_ms_ = -1.0;  // not given: runs compare by the set of outcomes
};

}  // namespace

std::unique_ptr<Command> make_sensitivity_command() { return std::make_unique<SensitivityCommand>(); }

}  // namespace railcrash::cli
