#include "mresim/app/threads.hpp"

#include <omp.h>

namespace mresim::app {

int configure_threads(long requested) {
  // OpenMP's own default, captured before any change, so that 0 restores it.
  static const int all_cores = omp_get_max_threads();
  omp_set_num_threads(requested > 0 ? static_cast<int>(requested) : all_cores);
  return omp_get_max_threads();
}

}  // namespace mresim::app
