// `railcrash readings MODEL`: the design's whole study for every combination of open readings,
// scored against the published results (report Tables 11-17).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>

#include "command.hpp"
#include "common.hpp"
#include "railcrash/studies/readings.hpp"
#include "railcrash/studies/run_count.hpp"
#include "railcrash/studies/sensitivity.hpp"

namespace railcrash::cli {

namespace {

int run_readings_study(const std::string& path, const std::string& design_option, const std::string& readings_path, int jobs,
                       bool first_order_only, double run_limit, std::size_t max_runs, const std::string& out_dir) {
  using namespace railcrash;
  check_output_folder(out_dir);
  const std::string design_path = design_option == "report" ? default_design_path(path) : design_option;
  const SensitivityDesign design = load_design(design_path);
  const ReadingsPlan plan = load_readings(readings_path);
  ReadingsOptions options;
  options.study.jobs = jobs_to_run(jobs);
  options.study.second_order = !first_order_only;
  options.study.run_time_limit = run_limit;
  options.study.max_runs = max_runs;
  options.progress = [&plan](const ReadingsCombinationResult& r, std::size_t number, std::size_t total) {
    const auto& a = r.agreement.responses;
    std::fprintf(stderr, "[%zu/%zu] %s: R1 %.3f R2 %.3f R3 %.3f; rho R1 %.2f R2 %.2f; goals %d/%d; %d failed; %.0f s\n",
                 number + 1, total, plan.label(r.levels).c_str(), a[0].value, a[1].value, a[2].value, a[0].spearman,
                 a[1].spearman, r.agreement.goals_met, Agreement::kGoals, r.failed_runs, r.wall_seconds);
  };
  options.study.stop = &interrupted();
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

class ReadingsCommand final : public Command {
 public:
  CLI::App* add_to(CLI::App& program) override {
    CLI::App* command = program.add_subcommand(
        "readings", "reading study: the design's whole study for every combination of open readings, scored against "
                    "the published results (report Tables 11-17)");
    command->add_option("model", model_path_, "model file with a responses section")->required();
    command->add_option("--readings", readings_path_, "readings file (YAML: reading_study: 1, readings: [{name, levels}])")->required();
    add_design_option(*command, design_path_);
    add_jobs_option(*command, jobs_, JobsDefault::AllCores);
    add_first_order_option(*command, first_order_only_);
    add_run_limit_option(*command, run_limit_);
    add_max_runs_option(*command, max_runs_);
    add_out_folder_option(*command, out_dir_);
    return command;
  }

  int run(char** /*argv*/) override {
    return run_readings_study(model_path_, design_path_, readings_path_, jobs_, first_order_only_, run_limit_, max_runs_, out_dir_);
  }

 private:
  std::string model_path_, readings_path_, design_path_, out_dir_;
  int jobs_ = 0;
  bool first_order_only_ = false;
  double run_limit_ = 0.0;
  std::size_t max_runs_ = kDefaultMaxRuns;
};

}  // namespace

std::unique_ptr<Command> make_readings_command() { return std::make_unique<ReadingsCommand>(); }

}  // namespace railcrash::cli
