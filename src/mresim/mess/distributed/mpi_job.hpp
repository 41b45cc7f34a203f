#pragma once

// The MPI job a `mresim run` process belongs to (docs/mpi.md): started by mpirun with P > 1
// processes, the 3D runs split every relaxation's evaluations over them; rank 0 does
// everything else (files, messages) and the others compute alongside it.

#include <string>

namespace mresim::mess {

struct MpiJob {
  int rank = 0;
  int size = 1;
};

// True when this process was started by an MPI launcher (mpirun sets OMPI_COMM_WORLD_SIZE,
// PMIX_RANK or PMI_SIZE). A plain `mresim run` is not, and needs no MPI at all.
bool started_by_mpi_launcher();

// This process's rank and the job's size: {0, 1} unless started by an MPI launcher, in which
// case MPI (with PETSc) is started now if it was not yet.
MpiJob mpi_job();

// Whether any process of the job has `flag` set (collective when the job has more than one
// process: all must call it at the same point).
bool any_process(bool flag);

// The largest of the processes' `value`s (collective as any_process). A stop signal that
// reached only some processes is known to all by its number: largest_over_processes(
// app::stop_signal()).
int largest_over_processes(int value);

// Collective: rank 0's `text` on every process (unchanged when the job has one process).
std::string broadcast_text(const std::string& text);

// Ends every process of the job with `status` (MPI_Abort): for an error on one process while
// the others may be waiting for it. Returns only when the job has one process.
void abort_job(int status);

}  // namespace mresim::mess
