#include "mresim/app/threads.hpp"

#include <fmt/format.h>
#include <omp.h>

#include <algorithm>
#include <stdexcept>

namespace mresim::app {

namespace {
constexpr int kOversubscription = 4;
int hardware_threads() { return std::max(1, omp_get_num_procs()); }
}  // namespace

int max_threads() { return kOversubscription * hardware_threads(); }

std::string threads_allowed() {
  return fmt::format(
      "must be between 0 and {} (at most {} x the {} hardware threads of this machine; 0 = all "
      "cores)",
      max_threads(), kOversubscription, hardware_threads());
}

int configure_threads(long requested) {
  // OpenMP's own default, captured before any change, so that 0 restores it.
  static const int all_cores = omp_get_max_threads();
  if (requested < 0 || requested > max_threads()) {
    throw std::invalid_argument(fmt::format("threads = {}: {}", requested, threads_allowed()));
  }
  omp_set_num_threads(requested > 0 ? static_cast<int>(requested) : all_cores);
  return omp_get_max_threads();
}

}  // namespace mresim::app
