// `railcrash report RUN_DIR`: the run's report page; with two run folders or more, the runs side by side.
#include <cstdio>
#include <string>
#include <vector>

#include "command.hpp"
#include "common.hpp"
#include "railcrash/core/error.hpp"
#include "railcrash/report/report.hpp"

namespace railcrash::cli {

int write_run_report(const std::string& run_dir, double cfc, double force_cfc, bool pdf) {
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

namespace {

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

class ReportCommand final : public Command {
 public:
  CLI::App* add_to(CLI::App& program) override {
    CLI::App* command = program.add_subcommand("report", "write RUN_DIR/report.html: header, animation, event log, plots (one self-contained file); "
                                                         "with two run folders or more, one page of the runs side by side");
    command->add_option("run_dir", run_dirs_, "run folder (the --out of `railcrash run`); two or more: the runs side by side, "
                                              "differences to the first")->required();
    command->add_option("--out", out_, "side by side only: the page's path (default: compare_<A>_<B>.html beside the first run folder)");
    cfc_option_ = command->add_option("--cfc", cfc_, "channel frequency class of the acceleration plots (SAE J211-1: 60, 180, 600, 1000); "
                                                     "one run's report only")
        ->capture_default_str()->check(finite_number(60, 1000, false, false, "Hz"));
    command->add_option("--force-cfc", force_cfc_,
                        "channel frequency class of the element force plot (SAE J211-1 lists CFC 60 for barrier face forces); 0: unfiltered")
        ->capture_default_str()->check(finite_number(0, 1000, false, false, "Hz"));
    command->add_flag("--pdf", pdf_, "also print the page to RUN_DIR/report.pdf with headless Chromium (Debian's chromium on PATH)");
    return command;
  }

  int run(char** /*argv*/) override {
    if (run_dirs_.size() > 1 && cfc_option_->count() > 0)
      throw InputError("report --cfc sets the acceleration plots of one run's report; the page of runs side by side has none "
                       "(its acceleration table shows each run's summary.json peaks, CFC 60): leave out --cfc, or report each "
                       "run on its own");
    if (run_dirs_.size() > 1) return compare_command(run_dirs_, out_, force_cfc_, pdf_);
    if (!out_.empty())
      throw InputError("report --out names the page of runs side by side (two run folders or more); the report of one run "
                       "is written to " + run_dirs_[0] + "/report.html");
    return write_run_report(run_dirs_[0], cfc_, force_cfc_, pdf_);
  }

 private:
  std::vector<std::string> run_dirs_;
  std::string out_;
  double cfc_ = 60.0;
  CLI::Option* cfc_option_ = nullptr;
  double force_cfc_ = 60.0;
  bool pdf_ = false;
};

}  // namespace

std::unique_ptr<Command> make_report_command() { return std::make_unique<ReportCommand>(); }

}  // namespace railcrash::cli
