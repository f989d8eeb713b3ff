// `railcrash report RUN_DIR`: one self-contained HTML page (RUN_DIR/report.html) of a run folder.
//
// It reads what the folder holds (results.hpp, results/run_files.hpp): summary.json (header:
// model, integrator, status, t reached, wall time, steps, events, energy balance, R1-R3,
// override, each car's crush and CFC-filtered peak accelerations), model.json and
// timeseries.csv (the animation of the planar model: bodies as the polygons of their
// connection points, elements as lines coloured by force or by mode), events.csv (the event
// log, synchronised with the animation), accelerations.csv (filtered here at the class asked,
// CFC 60 by default) and energy.csv (the energy partition). The page inlines its script and
// style and the plotting library the build fetched from npm (assets.hpp), so it opens
// without network access.
//
// A run with --format hdf5 (results/hdf5_file.hpp) has timeseries.h5 in place of
// timeseries.csv, accelerations.csv, energy.csv and events.csv: the report reads its tables
// (Hdf5Reader, the library loaded at run time as for writing) and shows the same page; its run
// id is the file's run_id attribute. A timeseries.h5 that cannot be opened (cut short, not
// HDF5) or lacks the timeseries table throws InputError naming the file and HDF5's reason.
//
// Plotted bodies: the car bodies (names containing "body"), else every body. Element forces:
// every element output named force, *_force; the crash elements (anticlimber, crush_spring,
// draft_gear, coupler_end, couplings) are shown first and get force-deformation loops. Long
// series are decimated with decimate_minmax (peaks kept), animation frames uniformly.
//
// A folder of `railcrash converge`, `sensitivity`, `readings` or `sweep` (converge.csv,
// sensitivity.csv, readings.csv or runs.csv, no timeseries.csv) gets a page of its Markdown
// summaries (headings as headings) and CSV files as tables, the convergence chart
// (converge.svg), and charts the page draws from the CSV files with the plotting library
// (page/report.js): a sweep's responses against each factor with the main effects, points
// coloured by runs.csv's branch (issue 40) and branch changes marked; a sensitivity study's
// tornado charts (sensitivity_first_order.csv, sensitivity_branches.csv); a convergence study's
// error against cost (converge.csv). Columns are found by name: extra columns are shown in
// the tables and left out of the charts.
//
// options.pdf: the page is also printed to report.pdf (report/pdf.hpp).
//
// The header shows the run's provenance (results/provenance.hpp) from summary.json.
//
// Bad folders: a missing folder, one without timeseries.csv or without a single complete row in
// it, or one whose files are of two runs (the run ids of summary.json, timeseries.csv,
// model.json, accelerations.csv, energy.csv and events.csv differ), or one whose files are
// not regular files, are links or are above the size limits (folder_file.hpp), throws
// InputError (exit 2). summary.json and model.json are parsed as JSON (nlohmann-json; one that
// is not JSON is a problem and reads as null). Anything else that is missing or broken (no
// summary.json, a failed run, a truncated CSV row, no model.json from an older railcrash) is
// listed as a problem at the top of the page, and the page shows what there is.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace railcrash::report {

struct ReportOptions {
  double cfc = 60.0;                   // channel frequency class of the accelerations
  double force_cfc = 60.0;             // channel frequency class of the element force plot (0: unfiltered)
  std::size_t max_plot_points = 4000;  // per series
  std::size_t max_frames = 1000;       // animation frames (fewer for very large models)
  bool pdf = false;                    // also print the page to report.pdf (report/pdf.hpp: headless Chromium)
};

struct ReportResult {
  std::string path;                   // RUN_DIR/report.html
  std::vector<std::string> problems;  // shown at the top of the page
  std::size_t rows = 0;               // complete rows of timeseries.csv
  std::string study;                  // "converge", "sensitivity" or "readings" for a study folder (rows: its files)
  std::string pdf_path;               // RUN_DIR/report.pdf when options.pdf
};

ReportResult write_report(const std::string& run_dir, const ReportOptions& options = {});

/// `railcrash report RUN_A RUN_B [...] --out FILE.html` (issue 39 item 5): one page of two or
/// more run folders (CSV or HDF5) side by side. A table of each run's identity (folder, model,
/// integrator, status, t reached, --set settings), tables of summary.json's quantities with the
/// difference of each run to the first (absolute and in % of the first run's magnitude): car
/// crush per car, energy per crush zone and per car, the energy at the end, the car bodies' CFC 60
/// peak accelerations, responses R1-R3 and scenario criteria, every output's peak; the discrete
/// outcome signature of each run; and time-history charts with a line per run (car bodies'
/// displacement and velocity, crash elements' force at --force-cfc and deformation, each energy
/// column). Only the timeseries columns every run has are overlaid, the others are listed; runs
/// that share no column but t (different models) throw InputError. out_path "": the path of
/// default_comparison_path. result.rows: the number of runs.
ReportResult write_comparison(const std::vector<std::string>& run_dirs, const std::string& out_path,
                              const ReportOptions& options = {});

/// The side-by-side page's default path: beside the first run folder (in its parent folder),
/// compare_<A>_<B>[...].html of the folders' names (other characters than letters, digits, '-'
/// and '.' as '_', each name cut at 40 characters). Runs out/a and out/b: out/compare_a_b.html.
std::string default_comparison_path(const std::vector<std::string>& run_dirs);

/// Whether this build inlines a plotting library (npm was available at build time).
bool have_plotting_library();

}  // namespace railcrash::report
