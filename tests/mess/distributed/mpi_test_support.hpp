#pragma once

// Helpers of the distributed tests: every process runs the same checks in the same order (the
// calls under test are collective), and a check fails on every process when it fails on any,
// so that no process waits for another that gave up.

#include <petscsys.h>  // MPI, without its C++ bindings

#include <algorithm>
#include <cmath>

#include "mresim/mess/solvers/amg_preconditioner.hpp"

namespace mresim::mess::testing {

// True on every process when `ok` holds on every process.
inline bool everywhere(bool ok) {
  int mine = ok ? 1 : 0;
  int all = 0;
  MPI_Allreduce(&mine, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  return all == 1;
}

inline int world_size() {
  initialise_petsc();
  int size = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  return size;
}

inline int world_rank() {
  initialise_petsc();
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  return rank;
}

inline double relative_difference(double a, double b) {
  return std::abs(a - b) / std::max(std::abs(b), 1e-300);
}

}  // namespace mresim::mess::testing
