#include "railcrash/studies/sweep_mpi.hpp"

#include <mpi.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "railcrash/core/error.hpp"
#include "railcrash/core/folder_lock.hpp"
#include "railcrash/core/table_text.hpp"
#include "railcrash/core/whole_file.hpp"
#include "railcrash/model/model_io.hpp"

namespace railcrash {

namespace {

constexpr int kResultTag = 1;  // worker -> rank 0: "NUMBER\nLINE" (a finished run), "NUMBER\n" (interrupted) or "-1\n" (ready)
constexpr int kWorkTag = 2;    // rank 0 -> worker: a run number, or -1: no more work
// Rank 0 waits for messages by polling with this sleep [ms], so it leaves the cores to the
// workers (OpenMPI's blocking receive spins).
constexpr int kPollMs = 2;

std::string receive_text(int& source) {
  MPI_Status status;
  for (int flag = 0;;) {
    MPI_Iprobe(MPI_ANY_SOURCE, kResultTag, MPI_COMM_WORLD, &flag, &status);
    if (flag) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(kPollMs));
  }
  int size = 0;
  MPI_Get_count(&status, MPI_CHAR, &size);
  std::string text(static_cast<std::size_t>(size), '\0');
  MPI_Recv(text.data(), size, MPI_CHAR, status.MPI_SOURCE, kResultTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  source = status.MPI_SOURCE;
  return text;
}

void send_text(const std::string& text) {
  MPI_Send(text.data(), static_cast<int>(text.size()), MPI_CHAR, 0, kResultTag, MPI_COMM_WORLD);
}

std::string broadcast(std::string text) {
  long size = static_cast<long>(text.size());
  MPI_Bcast(&size, 1, MPI_LONG, 0, MPI_COMM_WORLD);
  text.resize(static_cast<std::size_t>(size));
  MPI_Bcast(text.data(), static_cast<int>(size), MPI_CHAR, 0, MPI_COMM_WORLD);
  return text;
}

/// One run on this rank (at most one per rank at a time): its runs.csv line, or nothing when
/// the caller's stop flag interrupted it.
std::string run_here(const SweepPlan& plan, const std::string& model_path, const CheckedYamlText& model_text,
                     const std::string& directory, const SweepOptions& options, const SweepRunSpec& spec, std::size_t k) {
  BatchOptions batch;
  batch.run_time_limit = options.run_time_limit;
  batch.stop = options.stop;
  SweepRow row;
  char folder[32];
  std::snprintf(folder, sizeof folder, "/runs/%04zu", k);
  const std::vector<BatchRunState> state = run_batch(
      1, [&](std::size_t, const RunControl& control) {
        row = run_sweep_spec(plan, model_path, model_text, spec, control, options.keep_runs ? directory + folder : "");
      },
      batch);
  return state[0] == BatchRunState::finished ? sweep_csv_line(plan, k, spec, row) : std::string();
}

/// Rank 0: hands out the runs not done yet, one at a time, to the ranks that ask and to a
/// thread of its own (rank 0 runs too), and writes the files.
int coordinate(const SweepPlan& plan, const std::string& model_path, const CheckedYamlText& model_text,
               const std::string& directory, const SweepOptions& options, int ranks) {
  const FolderLock folder_lock(directory);  // one sweep per folder
  if (const std::string note = folder_lock.removal_note(directory); !note.empty() && options.note) options.note(note + "\n");
  const SweepRunGenerator generator(plan, model_path, model_text.text());
  SweepResult result = start_sweep(plan, generator, directory, options.resume);
  if (const std::string note = sweep_start_note(result, directory); !note.empty() && options.note) options.note(note);
  std::optional<FileWriteError> write_failure;  // a row that could not be appended: no more runs are handed out
  // The runs not done, in order, handed out one at a time: the run numbers resumed are skipped,
  // nothing is held for the others.
  std::vector<std::size_t> resumed_numbers;
  for (const auto& [k, line] : result.lines) resumed_numbers.push_back(k);
  auto next_resumed = resumed_numbers.begin();
  std::mutex mutex;  // guards next, done and result.lines, shared with rank 0's own worker thread
  std::size_t next = 0, done = result.done();
  const auto take = [&]() -> long {
    const std::lock_guard<std::mutex> lock(mutex);
    if ((options.stop && options.stop->load()) || write_failure) return -1;
    while (next_resumed != resumed_numbers.end() && *next_resumed == next) ++next_resumed, ++next;
    if (next >= result.total) return -1;
    return static_cast<long>(next++);
  };
  const auto record = [&](long number, const std::string& line) {
    if (line.empty()) return;  // interrupted: run again on --resume
    const std::lock_guard<std::mutex> lock(mutex);
    if (write_failure) return;
    try {
      append_sweep_line(directory, line);
    } catch (const FileWriteError& e) {
      write_failure = e;
      return;
    }
    result.lines[static_cast<std::size_t>(number)] = line;
    ++done;
    if (options.progress) {
      const std::vector<std::string> fields = csv_fields(line);
      SweepRow row;
      row.status = fields[2 + plan.factors.size()];
      const std::size_t wall_field = 3 + plan.factors.size() + plan.responses.size();  // then message, outcomes, branch, ...
      row.wall_seconds = std::atof(fields[wall_field].c_str());
      row.message = fields[wall_field + 1];
      options.progress(static_cast<std::size_t>(number), row, done, result.total);
    }
  };
  std::thread own([&] {
    for (long k = take(); k >= 0; k = take())
      record(k, run_here(plan, model_path, model_text, directory, options, generator.spec(static_cast<std::size_t>(k)),
                         static_cast<std::size_t>(k)));
  });
  int working = ranks - 1;  // other ranks not yet told to stop
  while (working > 0) {
    int source = 0;
    const std::string text = receive_text(source);
    const std::size_t newline = text.find('\n');
    const long number = std::atol(text.substr(0, newline).c_str());
    if (number >= 0) record(number, text.substr(newline + 1));
    const long work = take();
    if (work < 0) --working;
    MPI_Send(&work, 1, MPI_LONG, source, kWorkTag, MPI_COMM_WORLD);
  }
  own.join();
  if (write_failure) throw *write_failure;
  write_sweep(plan, result, directory);
  const std::size_t failed = failed_sweep_runs(plan, result);
  std::printf("%zu of %zu runs done (%zu resumed), %zu failed, on %d MPI ranks; results in %s/ (runs.csv, summary.md)\n",
              result.done(), result.total, result.resumed, failed, ranks, directory.c_str());
  if (result.done() < result.total) std::printf("interrupted: run again with --resume to finish\n");
  return result.done() == result.total && failed == 0 ? 0 : 1;
}

/// Ranks above 0: ask for a run, run it, send its line, until told to stop.
void work(const SweepPlan& plan, const std::string& model_path, const CheckedYamlText& model_text, const std::string& directory,
          const SweepOptions& options) {
  const SweepRunGenerator generator(plan, model_path, model_text.text());  // run k made when it is handed out
  std::string message = "-1\n";
  for (;;) {
    send_text(message);
    long number = -1;
    MPI_Recv(&number, 1, MPI_LONG, 0, kWorkTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    if (number < 0) return;
    const std::size_t k = static_cast<std::size_t>(number);
    message = std::to_string(number) + "\n" + run_here(plan, model_path, model_text, directory, options, generator.spec(k), k);
  }
}

}  // namespace

int sweep_with_mpi(const std::string& model_path, const std::string& plan_path, const std::string& directory,
                   const SweepOptions& options) {
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  int status = 0;
  // Every rank reads the plan (so every rank has it) and rank 0's model text, so all run the
  // same model; a bad plan stops every rank before any run, and rank 0 says why.
  std::string model_text;
  SweepPlan plan;
  std::string problem;
  try {
    if (rank == 0) check_output_folder(directory);  // only rank 0 writes there
    plan = load_sweep_plan(plan_path, model_path);
    require_sweep_run_count(plan, options.max_runs);  // before a rank generates a run
    if (rank == 0) model_text = read_model_text(model_path);
  } catch (const InputError& e) {
    problem = e.what();
  }
  int bad = problem.empty() ? 0 : 1, any_bad = 0;
  MPI_Allreduce(&bad, &any_bad, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  if (any_bad) {
    if (rank == 0) std::fprintf(stderr, "error: %s\n", problem.empty() ? "a rank could not read the plan or model" : problem.c_str());
    MPI_Finalize();
    return 2;
  }
  model_text = broadcast(model_text);
  try {
    if (ranks == 1) {
      const SweepResult result = run_sweep(model_path, plan, directory, options);
      status = result.done() == result.total && failed_sweep_runs(plan, result) == 0 ? 0 : 1;
    } else {
      const CheckedYamlText checked = check_model_text(model_text, model_path);  // once per rank, for all its runs
      if (rank == 0) status = coordinate(plan, model_path, checked, directory, options, ranks);
      else work(plan, model_path, checked, directory, options);
    }
  } catch (const InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    MPI_Abort(MPI_COMM_WORLD, 2);
  } catch (const FileWriteError& e) {  // runs.csv or summary.md could not be written (a full disk)
    std::fprintf(stderr, "railcrash failed: %s\n", e.what());
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  MPI_Bcast(&status, 1, MPI_INT, 0, MPI_COMM_WORLD);
  MPI_Finalize();
  return status;
}

}  // namespace railcrash
