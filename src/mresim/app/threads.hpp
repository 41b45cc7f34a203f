#pragma once

#include <string>

namespace mresim::app {

// The most threads a run may ask for: 4 x the hardware threads of this machine. More threads
// than cores only slow a run down (at 5,000 threads a 4 s run takes minutes), and the OpenMP
// runtime fails outright far beyond that; a multiple of the cores still allows deliberate
// oversubscription for tests.
int max_threads();
// "must be between 0 and 8 (at most 4 x the 2 hardware threads of this machine; 0 = all cores)"
std::string threads_allowed();

// Sets the number of OpenMP threads for the rest of the program: `requested` > 0 is used as
// is, 0 means all cores (OpenMP's default, which honours OMP_NUM_THREADS). Returns the number
// of threads parallel regions will use. `requested` must be in [0, max_threads()] (checked by
// the callers, which know the key or option to name).
int configure_threads(long requested);

}  // namespace mresim::app
