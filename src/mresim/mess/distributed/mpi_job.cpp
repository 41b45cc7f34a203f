#include "mresim/mess/distributed/mpi_job.hpp"

#include <petscsys.h>  // MPI, without its C++ bindings

#include <algorithm>
#include <array>
#include <cstdlib>
#include <string>

#include "mresim/mess/solvers/amg_preconditioner.hpp"

namespace mresim::mess {

bool started_by_mpi_launcher() {
  constexpr std::array<const char*, 3> kLaunchVariables = {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK",
                                                           "PMI_SIZE"};
  return std::any_of(kLaunchVariables.begin(), kLaunchVariables.end(),
                     [](const char* name) { return std::getenv(name) != nullptr; });
}

MpiJob mpi_job() {
  if (!started_by_mpi_launcher()) return {};
  initialise_petsc();
  MpiJob job;
  MPI_Comm_rank(MPI_COMM_WORLD, &job.rank);
  MPI_Comm_size(MPI_COMM_WORLD, &job.size);
  return job;
}

bool any_process(bool flag) { return largest_over_processes(flag ? 1 : 0) != 0; }

int largest_over_processes(int value) {
  if (mpi_job().size == 1) return value;
  int largest = 0;
  MPI_Allreduce(&value, &largest, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  return largest;
}

std::string broadcast_text(const std::string& text) {
  if (mpi_job().size == 1) return text;
  auto length = static_cast<long long>(text.size());
  MPI_Bcast(&length, 1, MPI_LONG_LONG, 0, MPI_COMM_WORLD);
  std::string out = text;
  out.resize(static_cast<std::size_t>(length));
  MPI_Bcast(out.data(), static_cast<int>(length), MPI_CHAR, 0, MPI_COMM_WORLD);
  return out;
}

void abort_job(int status) {
  if (mpi_job().size > 1) MPI_Abort(MPI_COMM_WORLD, status);
}

}  // namespace mresim::mess
