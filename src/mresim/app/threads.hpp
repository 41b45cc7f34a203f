#pragma once

namespace mresim::app {

// Sets the number of OpenMP threads for the rest of the program: `requested` > 0 is used as
// is, 0 means all cores (OpenMP's default, which honours OMP_NUM_THREADS). Returns the number
// of threads parallel regions will use.
int configure_threads(long requested);

}  // namespace mresim::app
