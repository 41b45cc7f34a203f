#include "cli/mpi_world.hpp"

// The C API only: OpenMPI's mpi.h would otherwise pull in its deprecated C++ bindings, which
// live in a library (libmpi_cxx) that mresim does not link.
#define OMPI_SKIP_MPICXX 1   // NOLINT(cppcoreguidelines-macro-usage)
#define MPICH_SKIP_MPICXX 1  // NOLINT(cppcoreguidelines-macro-usage)
#include <mpi.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <string>

namespace mresim::cli {

namespace {

bool started_by_mpi_launcher() {
  constexpr std::array<const char*, 3> kLaunchVariables = {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK",
                                                           "PMI_SIZE"};
  return std::ranges::any_of(kLaunchVariables,
                             [](const char* name) { return std::getenv(name) != nullptr; });
}

}  // namespace

MpiWorld::MpiWorld() {
  if (!started_by_mpi_launcher()) return;
  int already = 0;
  MPI_Initialized(&already);
  if (already == 0) {
    MPI_Init(nullptr, nullptr);
    initialised_ = true;
  }
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  if (const char* local = std::getenv("OMPI_COMM_WORLD_LOCAL_SIZE")) {
    try {
      local_size_ = std::max(1, std::stoi(local));
    } catch (const std::exception&) {  // unexpected text: assume one rank here
    }
  }
}

MpiWorld::~MpiWorld() {
  if (initialised_) MPI_Finalize();
}

int MpiWorld::broadcast(int value) const {
  if (size_ > 1) MPI_Bcast(&value, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return value;
}

std::vector<int> MpiWorld::sum_on_root(const std::vector<int>& values) const {
  if (size_ == 1) return values;
  std::vector<int> sum(values.size(), 0);
  std::vector<int> in = values;
  MPI_Reduce(in.data(), sum.data(), static_cast<int>(in.size()), MPI_INT, MPI_SUM, 0,
             MPI_COMM_WORLD);
  return rank_ == 0 ? sum : values;
}

}  // namespace mresim::cli
