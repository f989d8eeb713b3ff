// `railcrash sweep` under mpirun/srun (built with RAILCRASH_MPI into railcrash-mpi, which the
// railcrash executable runs in its place under a launcher): rank 0 hands out run numbers
// one at a time to the ranks that ask and to a thread of its own (dynamic: a long run does not
// hold up the others; each rank does one run at a time, so start one rank per core), gathers
// the runs.csv lines and writes every file; with one rank it runs the sweep itself on --jobs
// threads.
#pragma once

#include <atomic>
#include <cstdlib>
#include <string>

#include "railcrash/studies/sweep.hpp"

namespace railcrash {

/// The process was started by an MPI launcher (OpenMPI's mpirun, or a PMI/PMIx one as srun).
/// Inline: the railcrash executable, which links no MPI, asks it too (src/cli/sweep_command.cpp).
inline bool launched_by_mpi() {
  for (const char* variable : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"})
    if (std::getenv(variable)) return true;
  return false;
}

/// The process's rank as its launcher gives it (OMPI_COMM_WORLD_RANK, PMI_RANK, PMIX_RANK), 0
/// when none does: for output that one process of the launch prints (sweep --dry-run), read
/// before MPI is initialized.
inline int launcher_rank() {
  for (const char* variable : {"OMPI_COMM_WORLD_RANK", "PMI_RANK", "PMIX_RANK"})
    if (const char* value = std::getenv(variable)) return std::atoi(value);
  return 0;
}

/// Runs the sweep over the MPI ranks; returns the command's exit status (2: bad input, printed
/// by rank 0 only). Calls MPI_Init and MPI_Finalize.
int sweep_with_mpi(const std::string& model_path, const std::string& plan_path, const std::string& directory,
                   const SweepOptions& options);

}  // namespace railcrash
