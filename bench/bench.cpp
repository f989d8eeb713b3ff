// railcrash benchmarks (not part of the test suite): `bench/run.sh` builds and runs them.
//
//   railcrash_bench consist [--cars 2,5,10,20,50,100] [--t-end 0.1]
//       consists of the report's car (railcrash consist) striking a standing consist: wall and
//       CPU time per simulated second, steps, residual evaluations, events, root returns,
//       integrator restarts, peak memory; then the fitted exponent of cost against cars.
//   railcrash_bench kernels [--cars 2,10,100]
//       the cost per unknown of one residual, Jacobian and root-function evaluation of the
//       consists at t = 0: whether the element kernels themselves scale linearly.
//   railcrash_bench memory [--mib 0.25,0.5,1,2,4,8,16,32,64]
//       this machine's read throughput against the size of the array read over and over:
//       where its caches end (a consist's working set passes them as it grows).
//   railcrash_bench numbers [--model models/barrier/two_car_barrier.yaml]
//       what an output row's numbers cost to format: the model's rows (body states, element
//       outputs, body accelerations, at full precision) through format_general12 against
//       snprintf's "%.12g" and std::to_chars(general, 12): ns per number and the ratios, and
//       whether every text is printf's.
//   railcrash_bench sensitivity [--design FILE]
//       the report's sensitivity study (base + first-order + second-order runs) with 1 and 2
//       jobs: wall time and speed-up.
//   railcrash_bench trains [--cars 200] [--model models/examples/emu3_wall.yaml]
//       expanding car types and trains (train_expansion.hpp): the model's first train made N
//       cars long (its car types in turn); parsing its text, the expansion alone (from the
//       parsed document to the flat one), and loading the train model against loading its
//       expanded flat text (fastest of 9 each) [ms].
// "located in a step": mode changes located on IDA's interpolating polynomial (each one
// O(1)); "restarts": mode changes the step could not absorb (IDAReInit).
// Every benchmark prints a table and appends it, with the machine's core count, the commit
// and the date, to bench/results.md.
#include <CLI/CLI.hpp>

#include <sys/resource.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <chrono>
#include <cstdint>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>
#include <thread>

#include "railcrash/model/model_io.hpp"
#include "railcrash/model/train_expansion.hpp"
#include "railcrash/results/buffered_file.hpp"
#include "railcrash/results/results.hpp"
#include "railcrash/results/run.hpp"
#include "railcrash/scenarios/consist.hpp"
#include "railcrash/solver/dae_system.hpp"
#include "railcrash/solver/integrator.hpp"
#include "railcrash/studies/sensitivity.hpp"

using namespace railcrash;

namespace {

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

double peak_memory_mib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

std::string today() {
  const std::time_t now = std::time(nullptr);
  char buffer[32];
  std::strftime(buffer, sizeof buffer, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  return buffer;
}

std::vector<int> parse_list(const std::string& text) {
  std::vector<int> values;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) values.push_back(std::stoi(item));
  return values;
}

/// Least-squares slope of log(y) against log(x).
double log_log_slope(const std::vector<double>& x, const std::vector<double>& y) {
  const double n = static_cast<double>(x.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double lx = std::log(x[i]), ly = std::log(y[i]);
    sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

void append_results(const std::string& path, const std::string& heading, const std::string& table,
                    const std::string& commit) {
  std::ofstream file(path, std::ios::app);
  file << "\n### " << heading << "\n\n" << today() << ", commit " << commit << ", "
       << std::thread::hardware_concurrency() << " cores\n\n" << table;
  if (!file) std::fprintf(stderr, "warning: could not append to %s\n", path.c_str());
  else std::printf("appended to %s\n", path.c_str());
}

/// The source tree's commit as bench/run.sh names it ("abc1234", "+changes" when tracked files
/// differ from it), read with git; "unknown" outside a git checkout.
std::string source_commit(const std::string& source) {
  const auto run = [](const std::string& command) {
    std::string out;
    if (FILE* pipe = popen(command.c_str(), "r")) {
      char buffer[256];
      while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) out += buffer;
      if (pclose(pipe) != 0) return std::string();
    }
    return out;
  };
  const std::string quoted = "'" + source + "'";  // (the source path is this build's, without quotes in it)
  std::string commit = run("git -C " + quoted + " rev-parse --short HEAD 2>/dev/null");
  while (!commit.empty() && (commit.back() == '\n' || commit.back() == '\r')) commit.pop_back();
  if (commit.empty()) return "unknown";
  if (!run("git -C " + quoted + " status --porcelain --untracked-files=no 2>/dev/null").empty()) commit += "+changes";
  return commit;
}

/// The 2N-car consist built from the template, through a model file (so it is loaded like any other).
LoadedModel load_consist(const std::string& template_path, int cars, const RunOverrides& overrides = {}) {
  const auto file = std::filesystem::temp_directory_path() / ("railcrash_bench_consist_" + std::to_string(cars) + ".yaml");
  {
    std::ofstream out(file);
    out << make_consist_model(template_path, cars);
  }
  LoadedModel loaded = load_model(file.string(), {}, option_settings(overrides));
  std::filesystem::remove(file);
  return loaded;
}

int consist_benchmark(const std::string& template_path, const std::vector<int>& cars, double t_end,
                      const std::string& results, const std::string& commit) {
  std::ostringstream table;
  char line[512];
  std::snprintf(line, sizeof line,
                "| cars per consist | bodies | unknowns | wall s | CPU s | CPU s per simulated s | steps | CPU ms per step | "
                "residuals | events | located in a step | restarts | peak MiB | KLU factor entries | R1 |\n"
                "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  table << line;
  std::fputs(line, stdout);
  std::vector<double> fit_cars, fit_cost;
  std::vector<double> all_cars, all_cost, all_step_cost, all_peak;  // every size that finished
  std::vector<std::array<double, kPhaseCount>> all_phases;           // their wall seconds by phase
  bool all_ok = true;
  for (const int n : cars) {
    RunOverrides overrides;
    overrides.t_end = t_end;
    overrides.output_interval = t_end / 100.0;
    const LoadedModel loaded = load_consist(template_path, n, overrides);
    const Model& model = loaded.model;
    const double cpu_start = cpu_seconds();
    const auto wall_start = std::chrono::steady_clock::now();
    const RunReport report = run_model(model, loaded.run_spec, "", nullptr, false, false, "csv", /*time_phases=*/true);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    const double cpu = cpu_seconds() - cpu_start;
    const RunStatistics& s = report.outcome.stats;
    const double peak_mib = peak_memory_mib();
    std::snprintf(line, sizeof line, "| %d | %d | %d | %.2f | %.2f | %.1f | %ld | %.3f | %ld | %ld | %ld | %ld | %.0f | %ld | %.3f |%s\n", n,
                  model.body_count(), model.size(), wall, cpu, cpu / report.outcome.t_reached, s.steps,
                  1e3 * cpu / static_cast<double>(std::max<long>(s.steps, 1)), s.residual_evaluations, s.events,
                  s.root_returns, s.reinitializations, peak_mib, s.factor_nonzeros,
                  report.responses.r1, report.outcome.ok ? "" : (" FAILED: " + report.outcome.message).c_str());
    table << line;
    std::fputs(line, stdout);
    std::fflush(stdout);
    all_ok = all_ok && report.outcome.ok;
    if (report.outcome.ok) {
      all_cars.push_back(n);
      all_cost.push_back(cpu / report.outcome.t_reached);
      all_step_cost.push_back(cpu / static_cast<double>(std::max<long>(s.steps, 1)));
      all_peak.push_back(peak_mib);
      all_phases.push_back(s.phase_seconds);
    }
    if (n >= 10 && report.outcome.ok) {
      fit_cars.push_back(n);
      fit_cost.push_back(cpu / report.outcome.t_reached);
    }
  }
  // Per segment between consecutive sizes: the exponent of CPU per simulated second and of
  // the cost per step, and the memory each added car costs (the peak grows with the sizes,
  // so the process's peak so far is this size's).
  if (all_cars.size() >= 2) {
    std::snprintf(line, sizeof line, "\n| cars | exponent of CPU per simulated s | exponent of CPU per step | MiB per added car |\n"
                  "|---|---|---|---|\n");
    table << line;
    std::fputs(line, stdout);
    for (std::size_t i = 1; i < all_cars.size(); ++i) {
      const std::vector<double> pair_cars{all_cars[i - 1], all_cars[i]};
      std::snprintf(line, sizeof line, "| %g -> %g | %.2f | %.2f | %.3f |\n", all_cars[i - 1], all_cars[i],
                    log_log_slope(pair_cars, {all_cost[i - 1], all_cost[i]}),
                    log_log_slope(pair_cars, {all_step_cost[i - 1], all_step_cost[i]}),
                    (all_peak[i] - all_peak[i - 1]) / (2.0 * (all_cars[i] - all_cars[i - 1])));
      table << line;
      std::fputs(line, stdout);
    }
  }
  // Where each size's wall time went (summary.json's stats.seconds), and per segment the
  // exponent of each phase: a phase whose calls are as many at both sizes but cost more than
  // in proportion shows which work grows faster than the model.
  if (!all_cars.empty()) {
    std::string head = "\n| cars | wall s by phase:", rule = "|---|";
    for (int p = 0; p < kPhaseCount; ++p) {
      head += std::string(p == 0 ? " " : " | ") + phase_name(static_cast<Phase>(p));
      rule += "---|";
    }
    table << head << " |\n" << rule << "\n";
    std::printf("%s |\n%s\n", head.c_str(), rule.c_str());
    const auto add_row = [&](const std::string& label, const auto& value) {
      std::string row = "| " + label;
      for (int p = 0; p < kPhaseCount; ++p) {
        char cell[32];
        std::snprintf(cell, sizeof cell, " | %.2f", value(static_cast<std::size_t>(p)));
        row += cell;
      }
      table << row << " |\n";
      std::printf("%s |\n", row.c_str());
    };
    for (std::size_t i = 0; i < all_cars.size(); ++i)
      add_row(std::to_string(static_cast<int>(all_cars[i])), [&](std::size_t p) { return all_phases[i][p]; });
    for (std::size_t i = 1; i < all_cars.size(); ++i) {
      char label[64];
      std::snprintf(label, sizeof label, "exponent %g -> %g", all_cars[i - 1], all_cars[i]);
      add_row(label, [&](std::size_t p) {
        const double a = all_phases[i - 1][p], b = all_phases[i][p];
        return a > 0.0 && b > 0.0 ? std::log(b / a) / std::log(all_cars[i] / all_cars[i - 1]) : 0.0;
      });
    }
  }
  if (fit_cars.size() >= 2) {
    std::snprintf(line, sizeof line, "\nCPU time per simulated second grows as cars^%.2f (least squares, %g to %g cars per consist; goal <= 1.1)\n",
                  log_log_slope(fit_cars, fit_cost), fit_cars.front(), fit_cars.back());
    table << line;
    std::fputs(line, stdout);
  }
  std::snprintf(line, sizeof line, "(simulated %g s of each; peak MiB is the process's peak so far, i.e. this size's, "
                "as sizes grow)\n", t_end);
  table << line;
  append_results(results, "Consist length (IDA)", table.str(), commit);
  return all_ok ? 0 : 1;
}

int kernels_benchmark(const std::string& template_path, const std::vector<int>& cars, const std::string& results,
                      const std::string& commit) {
  std::ostringstream table;
  char line[256];
  std::snprintf(line, sizeof line,
                "| cars per consist | unknowns | Jacobian nonzeros | residual ns per unknown | Jacobian ns per unknown | "
                "roots ns per unknown | elements | 4 KiB pages holding them |\n|---|---|---|---|---|---|---|---|\n");
  table << line;
  std::fputs(line, stdout);
  for (const int n : cars) {
    const Model model = load_consist(template_path, n).model;
    DaeSystem system(model);
    // Two states that differ in every body's angle by a round-off amount, evaluated in turn:
    // as in a run, every evaluation computes each body's rotation afresh (the cache in
    // DaeSystem::body_rotation would otherwise serve all but the first).
    std::array<std::vector<double>, 2> y{system.initial_state(), system.initial_state()};
    for (int b = 0; b < model.body_count(); ++b) y[1][static_cast<std::size_t>(3 * b + 2)] += 1e-12;
    std::vector<double> yp(y[0].size(), 0.0), r(y[0].size()), values(static_cast<std::size_t>(system.pattern().nonzeros()));
    std::vector<double> g(static_cast<std::size_t>(system.root_count()));
    // Repeats until a measurement has taken kMinimumCpuSeconds, the median of three such: with a
    // fixed count of 200000 / unknowns (16 at 100 cars) the first touches of the pages
    // (page faults of this virtual machine) made most of a measurement.
    constexpr double kMinimumCpuSeconds = 0.2;
    const auto time_per_unknown = [&](auto&& evaluate) {
      std::array<double, 3> per_unknown{};
      for (double& measured : per_unknown) {
        long repeats = 0;
        const double start = cpu_seconds();
        double elapsed = 0.0;
        do {
          evaluate(y[static_cast<std::size_t>(repeats % 2)].data());
          ++repeats;
        } while ((elapsed = cpu_seconds() - start) < kMinimumCpuSeconds);
        measured = 1e9 * elapsed / static_cast<double>(repeats) / system.size();
      }
      std::sort(per_unknown.begin(), per_unknown.end());
      return per_unknown[1];
    };
    const double residual = time_per_unknown([&](const double* state) { system.residual(0.0, state, yp.data(), r.data()); });
    const double jacobian =
        time_per_unknown([&](const double* state) { system.jacobian(0.0, 1e4, state, yp.data(), values.data()); });
    const double roots = time_per_unknown([&](const double* state) { system.roots(0.0, state, g.data()); });
    // How many memory pages a sweep over the element objects touches (their own bytes only).
    std::set<std::uintptr_t> pages;
    for (const auto& element : model.elements()) pages.insert(reinterpret_cast<std::uintptr_t>(element.get()) / 4096);
    std::snprintf(line, sizeof line, "| %d | %d | %d | %.1f | %.1f | %.1f | %zu | %zu |\n", n, system.size(),
                  system.pattern().nonzeros(), residual, jacobian, roots, model.elements().size(), pages.size());
    table << line;
    std::fputs(line, stdout);
    std::fflush(stdout);
  }
  append_results(results, "Element kernels per unknown", table.str(), commit);
  return 0;
}

int sensitivity_benchmark(const std::string& model_path, const std::string& design_path, const std::string& results,
                          const std::string& commit) {
  const SensitivityDesign design = load_design(design_path);
  std::ostringstream table;
  table << "| jobs | runs | failed | wall s |\n|---|---|---|---|\n";
  std::printf("| jobs | runs | failed | wall s |\n|---|---|---|---|\n");
  double one_job = 0.0;
  for (const int jobs : {1, 2}) {
    SensitivityOptions options;
    options.jobs = jobs;
    options.second_order = true;  // the whole study: base, 31 first-order and 8 second-order runs
    const auto start = std::chrono::steady_clock::now();
    const SensitivityResult result = run_sensitivity(model_path, design, options);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    int failed = result.base.ok ? 0 : 1;
    for (const auto& r : result.runs) failed += r.ok ? 0 : 1;
    for (const auto& r : result.second_order_runs) failed += r.ok ? 0 : 1;
    char line[256];
    std::snprintf(line, sizeof line, "| %d | %zu | %d | %.1f |\n", jobs,
                  result.runs.size() + result.second_order_runs.size() + 1, failed, wall);
    table << line;
    std::fputs(line, stdout);
    std::fflush(stdout);
    if (jobs == 1) one_job = wall;
    else {
      std::snprintf(line, sizeof line, "\nspeed-up with 2 jobs: %.2f\n", one_job / wall);
      table << line;
      std::fputs(line, stdout);
    }
  }
  append_results(results, "Sensitivity study (" + model_path + ")", table.str(), commit);
  return 0;
}

/// Per array size of `mib` MiB: the read throughput [GB/s] of summing the array over and over
/// (the hardware prefetches it), and the latency [ns] of a load whose address depends on the
/// one before (a walk through the array's 64-byte lines in a random cycle: no prefetch helps,
/// so each load waits for the level of the memory hierarchy the array fits in). Best of 5
/// rounds of at least 0.1 s each.
int memory_benchmark(const std::vector<double>& sizes_mib, const std::string& results, const std::string& commit) {
  std::ostringstream table;
  table << "| array MiB | read GB/s | ns per double | ns per dependent load |\n|---|---|---|---|\n";
  std::printf("| array MiB | read GB/s | ns per double | ns per dependent load |\n|---|---|---|---|\n");
  double sink = 0.0;
  for (const double mib : sizes_mib) {
    const auto count = static_cast<std::size_t>(mib * 1024.0 * 1024.0 / sizeof(double));
    std::vector<double> values(std::max<std::size_t>(count, 1));
    for (std::size_t i = 0; i < values.size(); ++i) values[i] = 1e-9 * static_cast<double>(i % 1000);
    double best = 0.0;  // [doubles per s]
    for (int round = 0; round < 5; ++round) {
      long passes = 0;
      const auto start = std::chrono::steady_clock::now();
      double elapsed = 0.0;
      do {
        double sum0 = 0.0, sum1 = 0.0, sum2 = 0.0, sum3 = 0.0;  // four chains: the loads, not the adds, limit
        std::size_t i = 0;
        for (; i + 4 <= values.size(); i += 4) {
          sum0 += values[i];
          sum1 += values[i + 1];
          sum2 += values[i + 2];
          sum3 += values[i + 3];
        }
        for (; i < values.size(); ++i) sum0 += values[i];
        sink += sum0 + sum1 + sum2 + sum3;
        ++passes;
        elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      } while (elapsed < 0.1);
      best = std::max(best, static_cast<double>(passes) * static_cast<double>(values.size()) / elapsed);
    }
    // The random cycle over the lines: next[line] is the index (in doubles) of the next line.
    constexpr std::size_t kLine = 64 / sizeof(double);
    const std::size_t lines = std::max<std::size_t>(values.size() / kLine, 2);
    std::vector<std::size_t> order(lines);
    for (std::size_t i = 0; i < lines; ++i) order[i] = i;
    std::mt19937_64 shuffle(12345);
    std::shuffle(order.begin(), order.end(), shuffle);
    std::vector<std::size_t> next(lines * kLine, 0);
    for (std::size_t i = 0; i < lines; ++i) next[order[i] * kLine] = order[(i + 1) % lines] * kLine;
    double best_latency = 1e300;  // [s per load]
    std::size_t at = order[0] * kLine;
    for (int round = 0; round < 5; ++round) {
      long loads = 0;
      const auto start = std::chrono::steady_clock::now();
      double elapsed = 0.0;
      do {
        for (int k = 0; k < 100000; ++k) at = next[at];
        loads += 100000;
        elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      } while (elapsed < 0.1);
      best_latency = std::min(best_latency, elapsed / static_cast<double>(loads));
    }
    sink += static_cast<double>(at);
    char line[128];
    std::snprintf(line, sizeof line, "| %g | %.1f | %.3f | %.1f |\n", mib, best * sizeof(double) * 1e-9, 1e9 / best,
                  1e9 * best_latency);
    table << line;
    std::fputs(line, stdout);
    std::fflush(stdout);
  }
  std::printf("(checksum %g)\n", sink);
  append_results(results, "Read throughput against array size", table.str(), commit);
  return 0;
}

/// The numbers a run's output rows print, unrounded: each row's body states, element outputs
/// and body accelerations (timeseries.csv and accelerations.csv hold them to twelve digits).
class RowNumbers : public RunObserver {
 public:
  explicit RowNumbers(const DaeSystem& system)
      : system_(system), acceleration_(static_cast<std::size_t>(system.body_unknowns())) {}
  void sample(double t, const double* y, const double* lambda, const double* /*quadratures*/, const double* outputs) override {
    ++row_count;
    numbers.push_back(t);
    numbers.insert(numbers.end(), y, y + 2 * system_.body_unknowns());
    numbers.insert(numbers.end(), outputs, outputs + system_.output_names().size());
    body_accelerations(system_, t, y, lambda, acceleration_.data(), scratch_);
    numbers.insert(numbers.end(), acceleration_.begin(), acceleration_.end());
  }
  std::vector<double> numbers;
  std::size_t row_count = 0;

 private:
  const DaeSystem& system_;
  std::vector<double> acceleration_;
  AccelerationScratch scratch_;
};

int numbers_benchmark(const std::string& model_path, const std::string& results, const std::string& commit) {
  const LoadedModel loaded = load_model(model_path);
  const SimulationSettings& simulation = loaded.run_spec.simulation;
  DaeSystem system(loaded.model);
  RowNumbers rows(system);
  const RunOutcome outcome = make_integrator(system, simulation)->run(simulation.t_end, simulation.output_interval, rows);
  if (!outcome.ok) throw std::runtime_error("the run failed: " + outcome.message);
  const std::vector<double>& numbers = rows.numbers;
  std::vector<char> text(numbers.size() * 33);
  // Every text against printf's, once.
  std::size_t differ = 0;
  for (const double x : numbers) {
    char ours[40], printf_text[40];
    *format_general12(ours, x) = '\0';
    std::snprintf(printf_text, sizeof printf_text, "%.12g", x);
    differ += std::strcmp(ours, printf_text) != 0 ? 1 : 0;
  }
  // The three formatters in turn, nine rounds; each one's fastest round [ns per number].
  const auto time_one = [&](auto format) {
    const auto start = std::chrono::steady_clock::now();
    char* at = text.data();
    for (const double x : numbers) {
      at = format(at, x);
      *at++ = ',';
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return 1e9 * seconds / static_cast<double>(numbers.size());
  };
  const auto ours = [](char* at, double x) { return format_general12(at, x); };
  const auto with_snprintf = [](char* at, double x) { return at + std::snprintf(at, 33, "%.12g", x); };
  const auto with_to_chars = [](char* at, double x) { return std::to_chars(at, at + 33, x, std::chars_format::general, 12).ptr; };
  std::array<double, 3> best{1e300, 1e300, 1e300};
  for (int round = 0; round < 9; ++round) {
    best[0] = std::min(best[0], time_one(ours));
    best[1] = std::min(best[1], time_one(with_snprintf));
    best[2] = std::min(best[2], time_one(with_to_chars));
  }
  std::ostringstream table;
  char line[512];
  std::snprintf(line, sizeof line,
                "%s: %zu numbers from %zu rows (body states, element outputs, body accelerations), %zu of them "
                "formatted otherwise than printf's \"%%.12g\"\n\n| formatter | ns per number (fastest of 9) | against "
                "format_general12 |\n|---|---|---|\n| format_general12 | %.1f | 1 |\n| snprintf \"%%.12g\" | %.1f | %.2f |\n"
                "| std::to_chars(general, 12) | %.1f | %.2f |\n",
                model_path.c_str(), numbers.size(), rows.row_count, differ,
                best[0], best[1], best[1] / best[0], best[2], best[2] / best[0]);
  table << line;
  std::fputs(line, stdout);
  append_results(results, "Formatting an output row's numbers", table.str(), commit);
  return differ == 0 ? 0 : 1;
}

/// Expansion time of an N-car train built from the car types of `model_path` (its first train's
/// cars repeated in turn), and what loading it costs against loading the same model flat.
int trains_benchmark(const std::string& model_path, int cars, const std::string& results, const std::string& commit) {
  YAML::Node root = YAML::LoadFile(model_path);
  const YAML::Node first = root["trains"][0];
  YAML::Node long_cars(YAML::NodeType::Sequence);
  for (int k = 0; k < cars; ++k) long_cars.push_back(YAML::Clone(first["cars"][k % first["cars"].size()]));
  YAML::Node train = YAML::Clone(first);
  train["cars"] = long_cars;
  YAML::Node trains(YAML::NodeType::Sequence);
  trains.push_back(train);
  root["trains"] = trains;
  root.remove("connections");
  root.remove("elements");
  YAML::Emitter emitter;
  emitter << root;
  const std::string text = emitter.c_str();
  const std::filesystem::path file = std::filesystem::temp_directory_path() / "railcrash_bench_train.yaml";
  std::ofstream(file) << text;
  const std::string flat = expand_model_file(file.string(), {}).text;
  // Each step 9 times: its fastest wall time and its least CPU time (this thread's: on a machine
  // shared with other work the wall time also counts the time the thread waited for a core).
  struct Times {
    double wall = 1e300, cpu = 1e300;  // [ms]
  };
  const auto thread_cpu = [] {
    timespec now{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
    return 1e3 * static_cast<double>(now.tv_sec) + 1e-6 * static_cast<double>(now.tv_nsec);  // [ms]
  };
  const auto fastest = [&](auto work) {
    Times best;
    for (int round = 0; round < 9; ++round) {
      const double cpu_start = thread_cpu();
      const auto start = std::chrono::steady_clock::now();
      work();
      best.wall = std::min(best.wall, 1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
      best.cpu = std::min(best.cpu, thread_cpu() - cpu_start);
    }
    return best;
  };
  std::size_t bodies = 0, elements = 0;
  Times expand;  // the expansion alone: from the parsed document to the flat one
  for (int round = 0; round < 9; ++round) {
    YAML::Node document = YAML::Load(text);
    TrainExpansion expansion;
    const double cpu_start = thread_cpu();
    const auto start = std::chrono::steady_clock::now();
    expand_trains(document, file.string(), expansion, [](const YAML::Node&) -> const std::string* { return nullptr; },
                  [](const YAML::Node&, const std::string&) {});
    expand.wall = std::min(expand.wall, 1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    expand.cpu = std::min(expand.cpu, thread_cpu() - cpu_start);
    bodies = document["bodies"].size();
    elements = document["elements"].size();
  }
  const Times parse = fastest([&] { YAML::Node document = YAML::Load(text); });
  const Times load_train = fastest([&] { load_model_text(text, file.string()); });
  const Times load_flat = fastest([&] { load_model_text(flat, "flat.yaml"); });
  std::filesystem::remove(file);
  char line[1024];
  std::snprintf(line, sizeof line,
                "%d cars from %s's car types: %zu bodies, %zu elements\n\n"
                "| step | ms wall (fastest of 9) | ms CPU (least of 9) |\n|---|---|---|\n"
                "| parse the train model's YAML | %.2f | %.2f |\n| expand the parsed document | %.2f | %.2f |\n"
                "| load the train model (parse, expand, build, finalize) | %.2f | %.2f |\n"
                "| load the expanded flat model | %.2f | %.2f |\n",
                cars, model_path.c_str(), bodies, elements, parse.wall, parse.cpu, expand.wall, expand.cpu, load_train.wall,
                load_train.cpu, load_flat.wall, load_flat.cpu);
  std::fputs(line, stdout);
  append_results(results, "Expanding car types and trains", line, commit);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"railcrash benchmarks (bench/README.md)"};
  app.require_subcommand(1);
  std::string source = RAILCRASH_SOURCE_DIR;
  std::string commit = "unknown", results = source + "/bench/results.md";
  app.add_option("--commit", commit, "commit id written with the figures (default: the source tree's, from git)");
  app.add_option("--results", results, "Markdown file the figures are appended to")->capture_default_str();

  std::string template_path = source + "/models/report/final_two_car.yaml", cars_text = "10,20,50,100,200";
  double t_end = 0.1;
  CLI::App* consist = app.add_subcommand("consist", "cost against consist length");
  consist->add_option("--template", template_path, "two-car model the consists are built from")->capture_default_str();
  consist->add_option("--cars", cars_text, "cars per consist, comma-separated")->capture_default_str();
  consist->add_option("--t-end", t_end, "simulated time of each run [s]")->capture_default_str();

  std::string kernel_cars = "2,10,100";
  CLI::App* kernels = app.add_subcommand("kernels", "cost per unknown of residual, Jacobian and roots against consist length");
  kernels->add_option("--template", template_path, "two-car model the consists are built from")->capture_default_str();
  kernels->add_option("--cars", kernel_cars, "cars per consist, comma-separated")->capture_default_str();

  std::string memory_mib = "0.25,0.5,1,2,4,8,16,32,64";
  CLI::App* memory = app.add_subcommand("memory", "read throughput against array size (where the caches end)");
  memory->add_option("--mib", memory_mib, "array sizes [MiB], comma-separated")->capture_default_str();

  std::string numbers_model = source + "/models/barrier/two_car_barrier.yaml";
  CLI::App* numbers = app.add_subcommand("numbers", "what formatting an output row's numbers costs");
  numbers->add_option("--model", numbers_model, "model whose rows are formatted")->capture_default_str();

  std::string design_path = source + "/models/report/sensitivity_design.yaml";
  CLI::App* sensitivity = app.add_subcommand("sensitivity", "the report's sensitivity study with 1 and 2 jobs");
  sensitivity->add_option("--design", design_path, "design file")->capture_default_str();

  int train_cars = 200;
  std::string train_model = source + "/models/examples/emu3_wall.yaml";
  CLI::App* trains = app.add_subcommand("trains", "expansion time of an N-car train of car types");
  trains->add_option("--cars", train_cars, "cars in the train")->capture_default_str();
  trains->add_option("--model", train_model, "model whose car types and first train are used")->capture_default_str();

  CLI11_PARSE(app, argc, argv);
  if (app.count("--commit") == 0) commit = source_commit(source);
  try {
    if (*consist) return consist_benchmark(template_path, parse_list(cars_text), t_end, results, commit);
    if (*kernels) return kernels_benchmark(template_path, parse_list(kernel_cars), results, commit);
    if (*memory) {
      std::vector<double> sizes;
      std::stringstream list(memory_mib);
      for (std::string item; std::getline(list, item, ',');) sizes.push_back(std::stod(item));
      return memory_benchmark(sizes, results, commit);
    }
    if (*numbers) return numbers_benchmark(numbers_model, results, commit);
    if (*sensitivity) return sensitivity_benchmark(template_path, design_path, results, commit);
    if (*trains) return trains_benchmark(train_model, train_cars, results, commit);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "railcrash_bench: %s\n", e.what());
    return 2;
  }
  return 0;
}
